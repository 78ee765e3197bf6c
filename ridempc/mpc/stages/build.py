"""What an MPC solve is built from and what it returns (:class:`~ridempc.mpc.rider.MpcRider`).

The loop copies what it has at the MPC's tick into :class:`BuildInputs`; the problem is
built, shaped (:class:`~ridempc.mpc.stages.base.ProblemShaper`) and solved from it in the
tick, the solver thread or the solver process (:mod:`ridempc.mpc.solver_process`), which
sends back a :class:`Built` (:func:`build_and_run`); the loop holds the solve under way as
a :class:`PendingSolve` until its plan takes over (:mod:`ridempc.mpc.plan_solver`).
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from concurrent.futures import Future
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.delay import predicted_start
from ridempc.mpc.handover import deviation
from ridempc.mpc.lean import LeanSteering
from ridempc.mpc.plan import Plan
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.shoe_observer import ShoeObserver
from ridempc.mpc.solver_process import Reply
from ridempc.mpc.state_map import PlanarFrame
from ridempc.trajopt.schedule import Contact

if TYPE_CHECKING:
    from ridempc.mpc.controller import LinearMpc
    from ridempc.mpc.stages.base import ProblemShaper

__all__ = ["BuildInputs", "Built", "PendingSolve", "build_and_run"]

Array = NDArray[np.float64]


class BuildInputs(NamedTuple):
    """What an MPC problem is built from, as the loop has it at the MPC's tick: the
    reference's time [s], the mapped state, the rates' drift (or None), the tick's time
    [s], the board's speed [m/s], the commanded roll at the horizon's nodes [rad], the
    turn over its steps [rad/s], the turn so far [rad], whether the rider coasts, whether
    the manoeuvre switched at this tick, the lean loop (a copy, or None), the shoes'
    observer (frozen, or None), the manoeuvre's kind, target and gain, the plan in force's
    first input (or None), the contacts of the last MPC step, the reference tracked
    when it changed at this tick (else None), whether any manoeuvre began at this tick,
    and the commanded lateral offset of the feet [m] (:mod:`~ridempc.mpc.foot_spread`);
    and the delay [s] from the tick to the plan's take-up over which ``x0`` is predicted
    (:mod:`~ridempc.mpc.delay`; ``t_ref`` and ``now`` are then the take-up's)."""

    t_ref: float
    x0: Array
    drift: Array | None
    now: float
    speed: float
    roll: Array
    turn: Array
    turned: float
    coasting: bool
    switched: bool
    lean: LeanSteering | None
    shoes: ShoeObserver | None
    manoeuvre: tuple[str, float, float]
    first_input: Array | None
    contacts: tuple[Contact, ...]
    reference: MotionReference | None
    began: bool
    lateral_offset: float
    delay: float = 0.0


class Built(NamedTuple):
    """An MPC problem built and solved: its plan, the contacts of its first step, the time
    spent building it [s], the QP's failures so far, the problem (None when sent back from
    the solver process without it) and how far its initial state lies from its reference
    (:func:`~ridempc.mpc.handover.deviation`) and how far its plan's next state lies from
    the next reference [-]."""

    plan: Plan
    contacts: tuple[Contact, ...]
    build_s: float
    failures: int
    problem: MpcProblem | None
    deviation: float
    expected: float


class PendingSolve(NamedTuple):
    """An MPC solve under way: the library frame its problem is in, the time of the state
    it starts from [s], the tick its plan takes over, and its built and solved problem to
    come (None when built and solved in the tick)."""

    frame: PlanarFrame
    time: float
    due: int
    reply: Future[Built] | Reply[Built] | None = None


def build_and_run(mpc: LinearMpc, shapers: Iterable[ProblemShaper], inputs: BuildInputs) -> Built:
    """The MPC problem of one tick built from ``inputs`` (and the build's own state: the QP
    and its warm start, a re-push's blend, the crouch's start, the static shifts kept by
    key), shaped by ``shapers`` in order and solved; in the loop's tick, the solver thread
    or the solver process, the same either way. A plan taken up ``inputs.delay`` [s] late
    starts from the state predicted at its take-up (:func:`~ridempc.mpc.delay.predicted_start`)."""
    started = time.perf_counter()
    if inputs.reference is not None:
        mpc.reference = inputs.reference
    x0 = inputs.x0
    if inputs.delay > 0.0 and inputs.first_input is not None:
        x0 = predicted_start(
            mpc.model,
            mpc.reference,
            inputs.t_ref,
            x0,
            inputs.first_input,
            inputs.drift,
            inputs.delay,
            mpc.settings.dt,
        )
    problem = mpc.problem(inputs.t_ref, x0, inputs.drift)
    for shaper in shapers:
        problem = shaper(problem, inputs)
    if mpc.qp is None:
        mpc.qp = mpc.build_qp(problem)
    build = time.perf_counter() - started
    qp = mpc.qp
    plan = qp.finish(qp.start(problem), qp.run())
    weights, reference = problem.state_weights, problem.state_reference
    gap = deviation(problem.initial_state, reference[0], weights)
    expected = deviation(plan.states[1], reference[1], weights)
    return Built(plan, problem.contacts[0], build, qp.failures, problem, gap, expected)
