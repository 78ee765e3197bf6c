"""The protocols of the rider's stages (:class:`~ridempc.mpc.rider.MpcRider`'s loop).

Each per-pair mechanism the pair file names under ``[stages.*]`` is a stage of one of these
kinds, and the rider lists and orders them in one place
(:meth:`~ridempc.mpc.rider_parts.RiderParts._build_stages`):

- :class:`TickObserver`: updated every control tick (500 Hz) from the sensors, the estimate
  and the feet's loads (``observers``: the drop's watch, the payload's loads), or, in
  ``wbc_observers``, after the whole-body QP from its output too (the shoes' observer, the
  push's watch);
- :class:`DriftSource`, a disturbance observer: at each MPC tick, a drift of the MPC's
  rates, the error its model makes that the observer has estimated (the deck's torque, the
  payload, a steady disturbance, the lean's centrifugal pull); the drifts are summed in the
  order listed;
- :class:`ProblemShaper`: one change to each MPC problem before it is solved (coasting, a
  commanded roll, a re-push's blend, the turn, the crouch and the lean, the shoes' lines,
  the swing's held forces), applied in order where the problem is built (the loop's tick,
  the solver thread or the solver process, whose copy keeps a stateful shaper's state);
- the command sources: the manoeuvre the command asks for
  (:class:`~ridempc.mpc.stages.manoeuvre_choice.ManoeuvreChoice`) and the commands read
  over the horizon (:class:`~ridempc.mpc.stages.commands.CommandHorizon`), the deck's roll
  held to the stance (:class:`~ridempc.mpc.stages.deck_roll.StanceRoll`), and the
  commanded roll and turn with the state in the library frame moved onto the board
  (:class:`~ridempc.mpc.stages.frame_follow.CommandedFrame`);
- the plans' observer: the handover's bookkeeping at each plan's take-up
  (:class:`~ridempc.mpc.stages.plan_watch.PlanWatch`);
- :class:`~ridempc.mpc.stages.triggers.HandoverTrigger` (``triggers``): why the MPC
  cannot ride this tick (:mod:`~ridempc.mpc.stages.triggers`), asked in order; a watch
  that observes every tick may be a trigger too.

To add a stage: write its module (one concept, its physics in the docstring), a class
meeting the protocol, build it in ``RiderParts.__init__`` (:mod:`ridempc.mpc.rider_parts`)
from the pair file's stage (None when the pair does not name it) and add it to its
protocol's list in ``_build_stages`` (or
``_drift_sources``, ``_problem_shapers``, :func:`~ridempc.mpc.stages.triggers.handover_triggers`)
in the order it acts.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from ridempc.estimation import EstimatedState
    from ridempc.mpc.plan import Plan
    from ridempc.mpc.problem import MpcProblem
    from ridempc.mpc.stages.build import BuildInputs
    from ridempc.sim.sensors import SensorPacket
    from ridempc.wbc.targets import WbcOutput

__all__ = ["ControlTick", "DriftSource", "MpcTick", "ProblemShaper", "TickObserver", "present"]

Array = NDArray[np.float64]
Stage = TypeVar("Stage")


def present(*stages: Stage | None) -> tuple[Stage, ...]:
    """The stages the pair has (None: a stage it does not use), in the order given."""
    return tuple(stage for stage in stages if stage is not None)


class ControlTick(NamedTuple):
    """What the loop has at each control tick (500 Hz) for its observers: the sensors, the
    estimate (each shoe's heading read), each foot's load [-] (a fraction of its standing
    share), whether the backup law rides, the rider's diagnostics to write into, and this
    tick's whole-body QP output (None before it is solved)."""

    sensors: SensorPacket
    estimate: EstimatedState
    loads: Array
    on_backup: bool
    diagnostics: dict[str, float]
    wbc: WbcOutput | None = None


class TickObserver(Protocol):
    """A stage updated at every control tick."""

    def observe(self, tick: ControlTick) -> None:
        """Take this tick's readings."""
        ...


class MpcTick(NamedTuple):
    """What the loop has at an MPC tick (every 15th, 30 Hz) for its stages: the estimate
    (each shoe's heading read), the time [s], the board's speed [m/s], whether the rider
    balances (holds or coasts: no manoeuvre's accelerations), the plan in force (or None)
    and the time it was solved from [s], the library frame's turn since that plan's [rad],
    whether the plan is not being followed (the backup rides, or a solve is under way), and
    the rider's diagnostics to write into."""

    estimate: EstimatedState
    now: float
    speed: float
    balancing: bool
    plan: Plan | None
    plan_time: float
    frame_turn: float
    held: bool
    diagnostics: dict[str, float]


class DriftSource(Protocol):
    """A disturbance observer: the drift it adds to the MPC's rates at an MPC tick."""

    def drift(self, tick: MpcTick, x0: Array) -> Array | None:
        """The drift [state units/s] for the mapped state ``x0``, or None for none."""
        ...


class ProblemShaper(Protocol):
    """One change to the MPC's problem before it is solved."""

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        """``problem`` shaped, from what the loop had at its tick (``inputs``)."""
        ...
