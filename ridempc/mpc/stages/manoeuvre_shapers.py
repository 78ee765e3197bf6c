"""The problem shapers of the manoeuvre (:class:`~ridempc.mpc.stages.base.ProblemShaper`),
in the order they act:

1. :class:`Coasting`: a board coasting after its push-off (or a re-push before its first
   push) rides at the board's speed, not the reference's
   (:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.coasting`); from a re-push's first push
   the planned gain over the board's speed, anchored there, and the held speed's outer
   loop's gain (:mod:`~ridempc.mpc.push_gain`);
2. :class:`RollCommand`: the commanded deck roll laid over the reference, its rider states
   shifted to balance it;
3. :class:`RepushBlend`: a re-push's reference blended in from where the coast left the
   rider (:mod:`~ridempc.mpc.switch_blend`);
4. :class:`Turn`: the reference turned at the commanded yaw rates.
"""

from __future__ import annotations

import numpy as np

from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.manoeuvre import REPUSH, ManoeuvreSelector, StateLayout
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.push_gain import PushAnchor, shifted_speeds
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.stages.build import BuildInputs
from ridempc.mpc.switch_blend import SwitchBlend

__all__ = ["Coasting", "RepushBlend", "RollCommand", "Turn"]


class RepushBlend:
    """A re-push's reference blended in over its first steps; any new manoeuvre ends the
    blend (a re-push starts its own)."""

    def __init__(self, mpc: LinearMpc, layout: StateLayout) -> None:
        self._mpc, self._layout = mpc, layout
        self._blend: SwitchBlend | None = None

    @property
    def reference(self) -> MotionReference:
        """The reference the MPC tracks (the re-push's entry during one)."""
        return self._mpc.reference

    def running(self, inputs: BuildInputs) -> bool:
        """Whether a blend runs through this build (not ended by a manoeuvre begun)."""
        return self._blend is not None and not inputs.began

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        t_ref = inputs.t_ref
        if inputs.began:
            self._blend = None
        if inputs.switched:
            reference = self._mpc.reference
            self._blend = SwitchBlend.at_switch(problem, reference, self._layout, t_ref)
        if self._blend is not None:
            problem = self._blend(problem, t_ref)
            self._blend = None if self._blend.done(t_ref) else self._blend
        return problem


class Coasting:
    """The steady ride slowed to the coasting board's speed; a re-push before its first
    push (while its blend runs) coasts too, its speeds scaled to the board's: the entry's
    planned body speed, faster than a deck that slows more than its model, had the MPC push
    the body forward and brake the deck. From the first push: the planned gain, anchored
    there, and the outer loop's (:class:`~ridempc.mpc.push_gain.PushAnchor`)."""

    def __init__(self, layout: StateLayout, blend: RepushBlend) -> None:
        self._layout, self._blend = layout, blend
        self._anchor = PushAnchor()

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        if inputs.began:
            self._anchor.reset()
        if inputs.coasting or self._blend.running(inputs):
            return ManoeuvreSelector.coasting(problem, self._layout, inputs.speed)
        board = self._layout.speed(self._layout.prefixes[0])
        if inputs.manoeuvre[0] != REPUSH or board is None:
            return problem
        nodes = np.arange(problem.state_reference.shape[0], dtype=float)
        times = inputs.t_ref + problem.dt * nodes
        entry = problem.state_reference[:, board]
        _, held, gain = inputs.manoeuvre
        reference = self._blend.reference
        extra = self._anchor.extra(reference, times, entry, inputs.speed, gain, held)
        return shifted_speeds(problem, self._layout, inputs.speed, extra)


class RollCommand:
    """The commanded deck roll over the horizon laid over the reference, the rider's states
    shifted by the statics of that roll (:meth:`~ridempc.mpc.controller.LinearMpc.static_shift`)."""

    def __init__(self, mpc: LinearMpc, layout: StateLayout) -> None:
        self._mpc, self._layout = mpc, layout

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        names, balance = self._layout.names, None
        if ManoeuvreSelector.commands_roll(names, inputs.roll):
            rider = self._layout.rider_states
            balance = self._mpc.static_shift(inputs.t_ref, names["board_roll"], rider)
        return ManoeuvreSelector.with_command(problem, names, inputs.roll, balance)


class Turn:
    """The reference turned at the commanded yaw rates, by the turn so far."""

    def __init__(self, layout: StateLayout) -> None:
        self._layout = layout

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        return ManoeuvreSelector.with_turn(problem, self._layout, inputs.turn, inputs.turned)
