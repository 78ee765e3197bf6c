"""The rider's plan take-up alone: where a solve runs and when its plan takes over
(:mod:`ridempc.mpc.plan_solver`), the plan in force and its age (:mod:`ridempc.mpc.plan_book`)
and the handover's watch over the plans (:mod:`ridempc.mpc.stages.plan_watch`)."""

from __future__ import annotations

from typing import Any, cast

import numpy as np
import pytest

from ridempc.errors import RidempcError
from ridempc.mpc.force_filter import ForceFilter
from ridempc.mpc.handover import RETURN_DEVIATION, RETURN_DWELL_S, Handover
from ridempc.mpc.plan import Plan
from ridempc.mpc.plan_book import STEPS_PER_S, PlanBook
from ridempc.mpc.plan_solver import PROCESS_MIN_LATENCY, PlanSolver
from ridempc.mpc.stages.build import BuildInputs, Built, PendingSolve
from ridempc.mpc.stages.plan_watch import STANDBY_WARMUP_S, PlanWatch
from ridempc.mpc.state_map import PlanarFrame
from ridempc.trajopt.schedule import Contact


def _plan(value: float = 1.0, fallback: bool = False) -> Plan:
    states = np.full((3, 2), value)
    return Plan(states, np.zeros((2, 2)), np.array([value, 2.0]), "solved", 0.001, fallback)


def _built(plan: Plan, deviation: float = 0.0, expected: float = 0.0) -> Built:
    return Built(plan, (Contact.BOARD,), 0.002, 0, None, deviation, expected)


def _solver(latency: int, where: str) -> tuple[PlanSolver, list[float]]:
    """A solver whose build returns a plan of the input's ``now``, the builds recorded."""
    built: list[float] = []

    def build(inputs: Any) -> Built:
        built.append(inputs.now)
        return _built(_plan(inputs.now))

    solver = PlanSolver(latency, build, build)
    solver.off_tick = where
    return solver, built


def _inputs(now: float) -> BuildInputs:
    return cast(BuildInputs, type("Inputs", (), {"now": now})())


@pytest.mark.parametrize("where", ["tick", "thread", "process"])
def test_a_plan_takes_over_at_its_tick_wherever_it_is_solved(where: str) -> None:
    """The first plan, and every plan at a latency of 0, is solved at once; a later one is
    under way until its take-up tick, then handed over once (a latency of 1 runs in the
    thread even where the process is asked for: it waits less there)."""
    at_once, _ = _solver(0, where)
    solve = PendingSolve(PlanarFrame(), 0.0, 0)
    first = at_once.start(solve, _inputs(0.0), first=False)
    assert first is not None and first.plan.states[0, 0] == 0.0 and at_once.pending is None
    solver, built = _solver(1, where)
    assert solver.start(solve, _inputs(0.0), first=True) is not None
    later = PendingSolve(PlanarFrame(), 0.5, 16)
    assert solver.start(later, _inputs(0.5), first=False) is None
    assert solver.due(15) is None and solver.pending is not None
    taken = solver.due(16)
    assert taken is not None and taken.due == 16 and solver.pending is None
    assert taken.reply is not None and taken.reply.result().plan.states[0, 0] == 0.5
    assert solver.due(17) is None and built == [0.0, 0.5]
    assert 1 < PROCESS_MIN_LATENCY and solver.worker is None  # no process below it
    solver.close()


def test_the_book_holds_the_plan_its_frame_and_its_age() -> None:
    """A plan taken up is in force in the frame it was solved in, aged in MPC steps from
    the state it was solved from, :math:`(t - t_0) \\cdot 30`; a plan that is not finite
    is refused after its time is recorded."""
    book = PlanBook(None)
    frame = PlanarFrame(0.3, (1.0, 2.0))
    built = _built(_plan(), deviation=0.4)
    book.record(built)
    plan = book.adopt(PendingSolve(frame, 1.0, 30), built)
    assert book.plan is plan and book.frame is frame and book.time == 1.0
    assert book.deviation == 0.4 and book.contacts == (Contact.BOARD,)
    assert book.age(1.0 + 0.5 / STEPS_PER_S) == pytest.approx(0.5)
    assert book.ms == [pytest.approx(3.0)] and book.qp_ms == [pytest.approx(1.0)]
    with pytest.raises(RidempcError, match="not finite"):
        book.adopt(PendingSolve(frame, 2.0, 60), _built(_plan(np.nan)))
    assert book.plan is plan and len(book.ms) == 2


def test_the_book_low_passes_the_first_inputs_forces() -> None:
    """With a force filter, the plan in force carries the filtered first input: a step of
    the input reaches :math:`1 - e^{-\\Delta t/\\tau}` of the way after one solve."""
    tau = 0.1
    book = PlanBook(ForceFilter(tau))
    book.adopt(PendingSolve(PlanarFrame(), 0.0, 0), _built(_plan(0.0)))
    plan = book.adopt(PendingSolve(PlanarFrame(), 1.0 / 30.0, 15), _built(_plan(1.0)))
    share = 1.0 - np.exp(-1.0 / 30.0 / tau)
    assert plan.first_input[0] == pytest.approx(share)


class _Handover:
    """The handover's state the watch reads and sets."""

    def __init__(self, on_backup: bool = False, starting: bool = False) -> None:
        self.on_backup, self.starting, self.standby_every = on_backup, starting, 1


def test_the_watch_proves_the_mpc_after_a_dwell_in_the_return_band() -> None:
    """Plans within the return band prove the MPC once they have lasted the dwell; the
    backup's standby runs every tick until then (and through the warm-up), then every
    ``standby_every`` ticks; a ride on the backup puts the MPC on probation again."""
    handover = _Handover()
    watch = PlanWatch(cast(Handover, handover), None, None, standby_every=15)
    # the plans expect the deviation they start from: no divergence beyond it
    good = _built(_plan(), 0.5 * RETURN_DEVIATION, 0.5 * RETURN_DEVIATION)
    times = np.arange(0.0, STANDBY_WARMUP_S + RETURN_DWELL_S + 0.1, 1.0 / 30.0)
    standby = []
    for t in times:
        watch.observe(float(t), good, com_height=0.9, commanded=True)
        standby.append(handover.standby_every)
    assert watch.probation.proven
    assert standby[0] == 1 and standby[-1] == 15
    far = _built(_plan(), 2.0 * RETURN_DEVIATION, 2.0 * RETURN_DEVIATION)
    watch.observe(float(times[-1]) + 0.1, far, com_height=0.9, commanded=True)
    assert handover.standby_every == 1  # out of the band: a handover may come
    handover.on_backup = True
    watch.observe(float(times[-1]) + 0.2, good, com_height=0.9, commanded=True)
    assert not watch.probation.proven
