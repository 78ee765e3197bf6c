"""Where the rider's MPC solves run and when their plans take over (:class:`PlanSolver`).

An MPC problem is built and solved from the state at its tick; its plan takes over
``plan_latency`` ticks later (the first plan, and every plan at a latency of 0, at once),
the ticks between following the previous plan. The solve runs in the tick, in the solver
thread beside the loop (:mod:`~ridempc.mpc.solver_thread`: its Python holds the loop's
lock, only OSQP's iterations run beside it) or in a child process on the other core
(:mod:`~ridempc.mpc.solver_process`), and its plan is waited for at its take-up tick
whichever it was, so that a ride does not depend on the machine: the same ride, bit for
bit, wherever it is solved.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future
from functools import cache, partial

from ridempc.mpc.solver_process import Reply, SolverProcess, forks
from ridempc.mpc.solver_thread import SolverThread
from ridempc.mpc.stages.build import BuildInputs, Built, PendingSolve

__all__ = ["OFF_TICK", "PROCESS_MIN_LATENCY", "PlanSolver"]

# Least plan_latency [ticks] whose solves go to the solver process: at 1 the loop takes the
# plan up after the next tick's simulation and estimate, about 0.5 ms after sending the
# state, where the process builds and solves in 2.3 ms (Hovershoes, median) and the thread,
# which overlaps OSQP's iterations with the loop (0.7 ms of building holds the lock), waits
# less (docs/tuning.md).
PROCESS_MIN_LATENCY: int = 2
# Where a late plan's solve may run: the process (from PROCESS_MIN_LATENCY on, else, or
# where it cannot fork, in a sweep's worker or off the main thread, the thread), the
# solver thread, or the tick itself.
OFF_TICK: tuple[str, ...] = ("process", "thread", "tick")


@cache
def _solver_thread() -> SolverThread:
    """The thread the MPC's solves run in beside the control loop, one for the process
    (made at its first use): a rider per ride, and rides one after another (``compare``'s
    seeds), would otherwise each leave an idle thread behind."""
    return SolverThread("mpc")


class PlanSolver:
    """The MPC's solves, each run where :attr:`off_tick` says and held until its plan's
    take-up tick.

    Args:
        latency: Ticks from the state a solve starts from to the tick its plan takes over.
        build: Builds and solves a problem in the loop's process (the tick or the thread).
        build_in_process: The same in the solver process (its reply may leave the problem
            out).
    """

    def __init__(
        self,
        latency: int,
        build: Callable[[BuildInputs], Built],
        build_in_process: Callable[[BuildInputs], Built],
    ) -> None:
        self.latency = latency
        self.off_tick = OFF_TICK[0]
        self._build = build
        self._build_in_process = build_in_process
        self.worker: SolverProcess[BuildInputs, Built] | None = None
        self.pending: PendingSolve | None = None  # the solve under way, until its tick

    def start(self, solve: PendingSolve, inputs: BuildInputs, first: bool) -> Built | None:
        """The solve of ``inputs`` started: built and solved now (and returned) at a
        latency of 0 or for the ``first`` plan, else left under way until ``solve.due``."""
        if self.latency == 0 or first:  # the first plan is waited for
            return self._build(inputs)
        self.pending = solve._replace(reply=self._submit(inputs))
        return None

    def due(self, tick: int) -> PendingSolve | None:
        """The solve whose plan takes over at ``tick`` (its reply waited for by the
        caller), or None; no longer pending once returned."""
        solve = self.pending
        if solve is None or tick < solve.due:
            return None
        self.pending = None
        return solve

    def _submit(self, inputs: BuildInputs) -> Future[Built] | Reply[Built]:
        """The build and solve of ``inputs`` started where ``off_tick`` says."""
        where = self.off_tick
        process = where == "process" and self.latency >= PROCESS_MIN_LATENCY
        if process and (self.worker is not None or forks()):
            if self.worker is None:
                self.worker = SolverProcess(self._build_in_process)
            return self.worker.submit(inputs)
        if where in ("process", "thread"):
            return _solver_thread().submit(partial(self._build, inputs))
        future: Future[Built] = Future()
        future.set_result(self._build(inputs))
        return future

    def close(self) -> None:
        """End the solver process, if one was started (at the end of a ride)."""
        if self.worker is not None:
            self.worker.close()
            self.worker = None
