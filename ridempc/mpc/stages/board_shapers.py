"""The problem shapers of the board (:class:`~ridempc.mpc.stages.base.ProblemShaper`), after
the manoeuvre's (:mod:`~ridempc.mpc.stages.manoeuvre_shapers`), in the order they act:

1. :class:`CrouchShaper`: on a board turned by a bar the legs push (the Segway's knee bar),
   the rider crouches into the robot's riding keyframe to reach it (:mod:`~ridempc.mpc.lean`);
2. :class:`LeanShaper`: and leans into it: the lean loop's offset moves the reference's
   centre of mass sideways, and the frame's turn turns its headings;
3. :class:`ShoeLines`: on the Hovershoes each shoe's reference on its spread line, its
   heading turned towards it (:mod:`~ridempc.mpc.guidance`), its foot's place along it and
   its drag (:class:`~ridempc.mpc.shoe_observer.ShoeObserver`);
4. :class:`HeldForces`: while a foot swings and no contact changes from the last tick, the
   first step's deck forces drawn to the last plan's (:mod:`~ridempc.mpc.input_rate`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.foot_spread import spread_lines
from ridempc.mpc.guidance import steer_onto_lines
from ridempc.mpc.input_rate import hold_first_input
from ridempc.mpc.lean import Crouch
from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.stages.build import BuildInputs
from ridempc.mpc.statics import StaticShift
from ridempc.trajopt.schedule import Contact

__all__ = ["CrouchShaper", "HeldForces", "LeanShaper", "ShoeLines"]


class CrouchShaper:
    """The reference's centre of mass lowered into the riding crouch (row ``com_z``)."""

    def __init__(self, crouch: Crouch, com_z: int) -> None:
        self.crouch, self._com_z = crouch, com_z

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        return self.crouch.lower(problem, self._com_z, inputs.now)


class LeanShaper:
    """The lean loop's (its copy in ``inputs``) sideways offset and turn laid over the
    reference; the forces' balance per metre of offset found once per manoeuvre at its
    first lean (the stance does not change over a speed change on the Segway; found at
    every tick of a ramp, where the reference moves, it took 1.2 ms of the MPC tick)."""

    def __init__(self, mpc: LinearMpc, layout: StateLayout) -> None:
        self._mpc, self._layout = mpc, layout
        self._shift: tuple[tuple[str, float], StaticShift] | None = None

    def _balance(self, t_ref: float, manoeuvre: tuple[str, float]) -> StaticShift:
        """How the reference's forces move per metre of the lean's offset."""
        if self._shift is None or self._shift[0] != manoeuvre:
            names, rider = self._layout.names, self._layout.rider_states
            self._shift = (manoeuvre, self._mpc.static_shift(t_ref, names["com_y"], rider))
        return self._shift[1]

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        lean, names = inputs.lean, self._layout.names
        if lean is None:
            return problem
        if lean.offset != 0.0:
            balance = self._balance(inputs.t_ref, inputs.manoeuvre)
            problem = lean.lean(problem, names["com_y"], names["vy"], balance)
        return lean.turn(problem, self._layout)


class ShoeLines:
    """Each shoe's reference on its line: spread by the commanded lateral offset, its
    heading turned towards the line (with ``guidance``), its foot's place along it and its
    drag from the shoes' observer (its frozen copy in ``inputs``).

    Args:
        columns: Per shoe, its (x, y, heading, speed) columns in the MPC's state.
        guidance: Whether the headings are turned onto the lines.
    """

    def __init__(self, columns: Sequence[Sequence[int]], guidance: bool) -> None:
        self._columns, self._guidance = columns, guidance

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        shoes, columns = inputs.shoes, self._columns
        if shoes is None:
            return problem
        states = spread_lines(problem.state_reference, columns, inputs.lateral_offset)
        if self._guidance:
            states = steer_onto_lines(states, problem.initial_state, columns)
        states = shoes.shift_reference(states, columns)
        c = shoes.speed_drift(problem.c, problem.dt, [v for *_, v in columns])
        return replace(problem, state_reference=states, c=c)


class HeldForces:
    """While a foot swings and no contact changes from the last tick, the first step's
    deck forces drawn to the last plan's first input, with the pair's tolerance
    :attr:`~ridempc.mpc.pairs.MpcPair.swing_force_step` [N]."""

    def __init__(self, mpc: LinearMpc, step: float) -> None:
        self._mpc, self._step = mpc, step

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        first_input, contacts = inputs.first_input, problem.contacts[0]
        if first_input is None or Contact.SWING not in contacts or inputs.contacts != contacts:
            return problem
        index = self._mpc.reference.force_index
        weights = np.zeros(problem.nu)
        for i, contact in enumerate(contacts):
            if contact is Contact.BOARD:
                weights[index[i]] = 1.0 / self._step**2
        return hold_first_input(problem, first_input, weights)
