"""``ridempc bench``: MPC and WBC solve times on recorded problems, and other QP solvers.

For each robot-board pair with a pair file (:func:`ridempc.mpc.pairs.mpc_pair_names`):

1. **Record.** The ``mpc`` rider rides the pair's benchmark scenario
   (its pair file's ``bench_scenario``: a manoeuvre, not standing still, where the QPs are
   hardest; ``scenario`` overrides it) for ``seconds`` of simulated time (seed 0): every MPC
   problem (30 Hz) and every WBC input (estimate and targets, 500 Hz) is kept, and the
   loop's wall time gives the closed-loop **real-time factor** (simulated over wall time;
   above 1 is faster than real time). The ride's own MPC ticks are timed too (**MPC tick**:
   building the problem, linearisation and discretisation included, and solving it, inside
   the closed loop). A ride that falls early still gives its problems up to the fall; the
   table says how many. The ride's wall time is split into its **budget**, the mean wall
   time per control tick [ms] (the real-time budget is the tick's 2 ms): the simulation
   (physics at 1500 Hz, sensors, the board's firmware, the motor drivers, the judge's log)
   and the rider's estimator, MPC (its 30 Hz ticks spread over the 500 Hz ones: the time
   they take in the loop's own thread, building each problem, starting and finishing its
   solve, and waiting for a solve still running when its plan is due; OSQP's iterations
   run in a thread beside the loop), WBC (model, contacts, QP) and the rest of the rider's
   tick.
2. **MPC.** The recorded problems are solved again in order by a fresh
   :class:`~ridempc.mpc.qp.MpcQP` (OSQP, built once, updated in place, warm-started):
   median and p99 of the update-and-solve time [ms].
3. **WBC.** The recorded ticks are solved again by a fresh
   :class:`~ridempc.wbc.WholeBodyController`: median and p99 of model update + QP [ms].

   Steps 2 and 3 run :data:`PASSES` times, each from a fresh QP or WBC, so each pass does
   the same work (the same warm starts, the same iterations). The median and p99 are the
   first pass's wall times, as a controller would see them; the **best p99** is the p99 of
   each problem's fastest pass, the work itself without the machine's interruptions. On
   this 2-core virtual machine those are what makes the tail: the Hovershoes' whole-body
   ticks took 0.63 ms median in each of three passes and p99 1.07, 0.80 and 1.14 ms, but
   the slowest 30 ticks of one pass were not those of the next (one in common), and each
   tick's fastest pass gave a p99 of 0.69 ms.
4. **Other solvers.** The same WBC QPs (dense, a tick each) go to the registry's other
   solvers (OSQP in its warm workspace, proxqp from a cold start), objectives compared
   with the loop solver's.
   The same MPC QPs, :math:`\\min \\tfrac12 z^\\top P z` s.t.
   :math:`l \\le A z \\le u`, are handed to each other backend available here: the
   qpsolvers backends (``proxqp``, ``daqp``, ... with equality rows :math:`l = u` as
   equalities) and HPIPM through CasADi's ``conic`` interface (in its stage-wise OCP
   layout, see :func:`_stage_layout`); each is timed from a cold start per problem (no
   warm start, only the solve call), and its objective compared with OSQP's; and OSQP
   warm-started as in step 2 with each row in the class its bounds give it
   (``osqp, row classes by bounds``: the loop's QP holds each row in one class,
   :mod:`ridempc.mpc.row_classes`), its first inputs compared with the loop QP's.

The JSON's ``controller_tick_p99_ms`` is the p99 of the rider's whole update per control
tick (estimator, MPC share, WBC and the rest), ``mpc_tick_p99_ms`` the MPC tick's (build
and solve), ``controller_physics_ratio`` the rider's wall time over the simulation's in the
same ride and ``reference_ms`` the machine reference; ``tick_phases_ms`` sorts the
controller ticks by their place in the MPC's period (:mod:`ridempc.tickphases`: the MPC's
tick, the plan's take-up and the backup's standby each have one, so the controller tick's
p99 is theirs; ``steady_p99`` is the other ticks'). ``tick_phases_cpu_ms`` sorts the same
ticks' CPU time of the loop's thread and ``cpu_real_time_factor`` is the simulated time
over that thread's CPU time in the loop: on a loaded machine, where wall times swing with
the other processes, these compare two versions (they leave out the solver process's and
thread's work, and the loop's waits for them). With ``profile`` (``--profile``) the
pair rides once more under :class:`~ridempc.tickprofile.PartProfiler`, and ``profile``
lists each part's hottest functions by their own time, ``profile_by_tick`` each kind of
control tick's (:data:`TICK_KINDS`: the MPC's tick, its build and solve, the plan's take-up,
the backup's standby, the other ticks), per tick of that kind.

The solvers are the registry's (:data:`ridempc.solvers.QP_KINDS`): the whole-body QPs
are solved, in the ride and in step 3, by its solver (DAQP), or by ``wbc_solver``
(``--wbc-solver osqp``: its real-time factor and budget are then OSQP's), and step 4
compares the others on the same problems: OSQP in a warm workspace of its own, replaying
them in order, the rest from a cold start.

Times are wall-clock on this machine and vary with its load and its speed of the moment,
which the budget table's **machine reference** records before each pair's ride
(:func:`reference_ms`, a fixed pure-Python loop, and its limits); the targets are an MPC
p99 of at most 5 ms and a WBC p99 of at most 1 ms.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ridempc.errors import RidempcError
from ridempc.heap import frozen_heap
from ridempc.interrupts import casadi_solve, osqp_returned
from ridempc.io import atomic_write_json
from ridempc.solvers import QP_KINDS, solve_dense
from ridempc.tickphases import tick_phases
from ridempc.tickprofile import DEFAULT_TOP, PartProfiler, profile_table

__all__ = ["PairBench", "bench", "bench_table"]

DEFAULT_SECONDS: float = 6.0
PASSES: int = 3  # the recorded problems are solved this many times (module docstring)
OSQP_BOUNDS_CLASSES: str = "osqp, row classes by bounds"  # the loop's OSQP before held classes


@dataclass
class PairBench:
    """One pair's figures (times in ms)."""

    pair: str
    scenario: str = ""
    wbc_solver: str = QP_KINDS["wbc"].solver
    mpc_problems: int = 0
    wbc_ticks: int = 0
    simulated_s: float = 0.0
    real_time_factor: float = float("nan")
    mpc_solve_median_ms: float = float("nan")
    mpc_solve_p99_ms: float = float("nan")
    mpc_tick_median_ms: float = float("nan")
    mpc_tick_p99_ms: float = float("nan")
    controller_tick_p99_ms: float = float("nan")
    controller_physics_ratio: float = float("nan")
    tick_phases_ms: dict[str, float] = field(default_factory=dict)
    cpu_real_time_factor: float = float("nan")
    tick_phases_cpu_ms: dict[str, float] = field(default_factory=dict)
    wbc_solve_median_ms: float = float("nan")
    wbc_solve_p99_ms: float = float("nan")
    mpc_solve_best_p99_ms: float = float("nan")
    wbc_solve_best_p99_ms: float = float("nan")
    wbc_failures: int = 0
    ride_status: str = ""
    budget_ms: dict[str, float] = field(default_factory=dict)
    reference_ms: float = float("nan")
    solvers: dict[str, dict[str, Any]] = field(default_factory=dict)
    wbc_solvers: dict[str, dict[str, Any]] = field(default_factory=dict)
    profile: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    profile_by_tick: dict[str, list[dict[str, Any]]] = field(default_factory=dict)


REFERENCE_ADDITIONS: int = 1_000_000  # the machine reference's loop (reference_ms)


def reference_ms(repeats: int = 5) -> float:
    """The machine's speed at the moment: the best of ``repeats`` timings of a fixed
    pure-Python loop (``REFERENCE_ADDITIONS`` integer additions) [ms]. The control loop is
    mostly Python, so its wall time goes with this: it tells a slow machine from slow code (on
    this 2-core machine the same loop ran up to 65 % slower from one hour to the next).
    Taken once before each ride, it does not see the machine change during the ride: a
    bench that read 28-33 ms gave real-time factors of 0.72-0.80 where the same code had
    run at about 1.0."""
    best = math.inf
    for _ in range(repeats):
        started = time.perf_counter()
        total = 0
        for i in range(REFERENCE_ADDITIONS):
            total += i
        best = min(best, time.perf_counter() - started)
    return 1e3 * best


def _stats(values: Sequence[float]) -> tuple[float, float]:
    if not values:
        return float("nan"), float("nan")
    ms = 1e3 * np.asarray(values)
    return float(np.median(ms)), float(np.percentile(ms, 99))


def _scenario_of(pair: str, scenario: str | None) -> str:
    """The scenario recorded for ``pair``: ``scenario`` if given, else its pair file's
    ``bench_scenario``."""
    from ridempc.pair_description import load_pair_description

    robot, board = pair.split("-", 1)
    return scenario or load_pair_description(robot, board).bench_scenario


BUDGET_PARTS: tuple[str, ...] = ("simulation", "estimator", "mpc", "wbc", "rider_rest")
# The kinds of control tick the profile is split by (:func:`_tick_kind`): the ride's first
# STANDBY_WARMUP_S, then the MPC's tick (its part in the loop), the plan's take-up, the
# backup's standby and the other ticks by their place in the MPC's period; the MPC's build
# and solve, wherever they run, are a kind of their own.
TICK_KINDS: tuple[str, ...] = ("warmup", "mpc_tick", "mpc_build", "take_up", "standby", "steady")


def _budget(result: Any, parts: dict[str, float], mpc: float) -> dict[str, float]:
    """The ride's mean wall time per control tick [ms], whole (``loop``) and by part
    (:data:`BUDGET_PARTS`; module docstring).

    Args:
        result: The ride (its loop's wall time and each rider update's time [s]).
        parts: Seconds spent in the estimator and in the WBC over the ride.
        mpc: Seconds the MPC spent in the control loop's thread (inside the rider's
            updates; its solves run in a thread of their own).
    """
    ticks = len(result.controller_times)
    if ticks == 0:
        return {}
    rider = float(np.sum(result.controller_times))
    spent = {
        "simulation": result.wall_time - rider,
        "estimator": parts["estimator"],
        "mpc": mpc,
        "wbc": parts["wbc"],
        "rider_rest": rider - parts["estimator"] - mpc - parts["wbc"],
    }
    return {"loop": 1e3 * result.wall_time / ticks} | {k: 1e3 * v / ticks for k, v in spent.items()}


def _timed(function: Callable[..., Any], spent: dict[str, float], key: str) -> Callable[..., Any]:
    """``function``, adding the wall time of each call to ``spent[key]`` [s]."""

    def timed(*args: Any) -> Any:
        started = time.perf_counter()
        try:
            return function(*args)
        finally:
            spent[key] += time.perf_counter() - started

    return timed


def _record(
    robot_name: str,
    board_name: str,
    scenario_name: str,
    seconds: float,
    wbc_solver: str = QP_KINDS["wbc"].solver,
    profiler: PartProfiler | None = None,
) -> tuple[Any, list, list, Any, dict[str, float]]:
    """One ride of the pair's rider, its MPC problems and WBC inputs kept; with
    ``profiler``, each part of its ticks (:data:`BUDGET_PARTS`) recorded into its own."""
    from ridempc.boards import load_board
    from ridempc.mpc.rider import MpcRider
    from ridempc.robots import load_robot
    from ridempc.scenarios import resolve_scenario
    from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
    from ridempc.sim.scene import build_scene
    from ridempc.sim.simulation import Simulation

    problems: list = []
    wbc_inputs: list = []

    class Recording(MpcRider):
        """The rider, its MPC problems kept: those built in the loop's thread (or the
        solver thread) as each plan is taken up; those of the solver process in the child,
        sent back together when the ride closes it (a problem is a few hundred kB: sent
        with each plan, reading it made the bench's take-up ticks slower than a ride's)."""

        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            self.kept: list = []  # the child's problems, in the child
            self.remote = 0  # plans taken up from the child, in the parent

        def _build_in_process(self, inputs: Any) -> Any:
            if inputs is None:  # the ride's end: every problem the child built
                return self.kept
            built = self._build_and_run(inputs)
            self.kept.append(built.problem)
            return built._replace(problem=None)

        def _adopt(self, solve: Any, built: Any) -> None:
            super()._adopt(solve, built)
            if built.problem is None:
                self.remote += 1
            else:
                problems.append(built.problem)

        def close(self) -> None:
            if self._worker is not None:
                pending = self._pending
                if pending is not None and pending.reply is not None:
                    pending.reply.result()  # each reply is read before the next submit
                kept = self._worker.submit(None).result()  # type: ignore[arg-type]
                problems.extend(kept[: self.remote])
            super().close()

    robot = load_robot(robot_name)
    rider = Recording(robot, board_name, wbc_solver=wbc_solver)
    # profiled, the MPC's problems are built in the loop's thread (the same ride): the
    # profiler sees that thread only
    rider.off_tick = "process" if profiler is None else "tick"
    parts = {"estimator": 0.0, "wbc": 0.0}  # [s] spent in each over the ride
    solve = _timed(rider.wbc.solve, parts, "wbc")

    def recording_solve(state: Any, targets: Any) -> Any:
        wbc_inputs.append((state, targets))
        return solve(state, targets)

    rider.wbc.solve = recording_solve  # type: ignore[method-assign]
    rider.estimator.update = _timed(  # type: ignore[method-assign]
        rider.estimator.update, parts, "estimator"
    )
    if profiler is not None:
        _profiled(rider, profiler)
    scenario = resolve_scenario(scenario_name, board_name).with_duration(seconds)
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, board=load_board(board_name))
    simulation = Simulation(scene, rider, scenario)
    if profiler is not None:
        profiler.start()
    try:
        result = simulation.run()
    finally:
        if profiler is not None:
            profiler.stop()
    return result, problems, wbc_inputs, rider, _budget(result, parts, rider.mpc_loop_seconds)


def _profiled(rider: Any, profiler: PartProfiler) -> None:
    """``rider``'s parts recorded each into its own profile (the simulation's is the
    loop's, the rest of the rider's its update's; the MPC's its ticks and the waits for
    their plans in the loop's thread)."""
    for owner, method, part in (
        (rider, "update", "rider_rest"),
        (rider.estimator, "update", "estimator"),
        (rider.wbc, "solve", "wbc"),
        (rider, "_mpc_tick", "mpc"),
        (rider, "_adopt_pending", "mpc"),
    ):
        setattr(owner, method, profiler.wrap(getattr(owner, method), part))
    solver = rider.solver  # the build and solve the plan solver runs, wherever it runs them
    solver._build = profiler.wrap_kind(solver._build, "mpc_build")
    update = rider.update

    def kind_then_update(sensors: Any, command: Any) -> Any:
        profiler.begin_tick(_tick_kind(rider, sensors.time))
        return update(sensors, command)

    rider.update = kind_then_update


def _tick_kind(rider: Any, now: float) -> str:
    """The kind (:data:`TICK_KINDS`) of the control tick ``rider`` is about to run at
    ``now`` [s], by its place in the MPC's period (:mod:`ridempc.tickphases`)."""
    from ridempc.mpc.rider import MPC_DIVIDER, STANDBY_WARMUP_S

    if now < STANDBY_WARMUP_S:
        return "warmup"
    phase = rider._tick % MPC_DIVIDER
    if phase == 0:
        return "mpc_tick"
    if rider.plan_latency and phase == rider.plan_latency:
        return "take_up"
    return "standby" if phase == rider.handover.standby_phase else "steady"


def _as_qpsolvers(
    p: sp.csc_matrix,
    a: sp.csc_matrix,
    lower: np.ndarray,
    upper: np.ndarray,
    q: np.ndarray | None = None,
) -> Any:
    """The QP in qpsolvers' form, rows with :math:`l = u` as equalities (``q``: zero)."""
    import qpsolvers

    equal = np.isclose(lower, upper)
    a = a.tocsr()
    rows_up = ~equal & np.isfinite(upper)
    rows_lo = ~equal & np.isfinite(lower)
    g = sp.vstack([a[rows_up], -a[rows_lo]]).tocsc()
    h = np.concatenate([upper[rows_up], -lower[rows_lo]])
    linear = np.zeros(p.shape[0]) if q is None else np.asarray(q, dtype=float)
    return qpsolvers.Problem(P=p, q=linear, G=g, h=h, A=a[equal].tocsc(), b=lower[equal])


def _objective(p: Any, z: np.ndarray, q: np.ndarray | None = None) -> float:
    """:math:`\\tfrac12 z^\\top P z + q^\\top z` (``q``: zero)."""
    return float(0.5 * z @ (p @ z) + (0.0 if q is None else q @ z))


def _figures(
    times: Sequence[float],
    gaps: Sequence[float],
    failures: int,
    first_input_diffs: Sequence[float] = (0.0,),
) -> dict[str, Any]:
    """One solver's row: solve times [s] as median and p99 [ms], failures, the largest
    objective gap to the reference solver's (relative) and the largest difference in the
    first input from the reference solver's (the MPC's :math:`u_0` in units of its
    tolerances, the WBC's torques [N m])."""
    median, p99 = _stats(times)
    return {
        "solve_median_ms": median,
        "solve_p99_ms": p99,
        "failures": failures,
        "objective_gap_max": float(np.max(gaps)) if gaps else None,
        "first_input_diff_max": float(np.max(first_input_diffs)) if first_input_diffs else None,
    }


def _gap(value: float, best: float) -> float:
    return abs(value - best) / max(abs(best), 1e-9)


def _other_solvers(qp: Any, problems: list) -> dict[str, dict[str, Any]]:
    import qpsolvers

    out: dict[str, dict[str, Any]] = {}
    data = []
    for problem in problems:
        data.append(qp.whole(problem))
    layout = _stage_layout(qp.horizon, qp.nx, qp.nu, qp.n_constraints)
    reference, reference_u0 = [], []
    first = slice((qp.horizon + 1) * qp.nx, (qp.horizon + 1) * qp.nx + qp.nu)  # u_0, scaled
    for p, a, lower, upper in data:
        qp_osqp = _as_qpsolvers(p, a, lower, upper)
        solution = qpsolvers.solve_problem(qp_osqp, solver="osqp", eps_abs=1e-6, eps_rel=1e-6)
        osqp_returned(solution.extras["info"].status_val)  # (ridempc.interrupts)
        found = solution.found and solution.x is not None
        reference.append(_objective(p, solution.x) if found else float("nan"))  # type: ignore[arg-type]
        reference_u0.append(solution.x[first] if found else None)  # type: ignore[index]
    for name in QP_KINDS["mpc"].compared:
        if name != "hpipm (casadi)" and name not in qpsolvers.available_solvers:
            continue
        times, gaps, failures, diffs = [], [], 0, []
        try:
            for (p, a, lower, upper), best, u0 in zip(data, reference, reference_u0, strict=True):
                if name == "hpipm (casadi)":
                    z, seconds = _solve_hpipm(p, a, lower, upper, layout)
                else:
                    problem = _as_qpsolvers(p, a, lower, upper)
                    started = time.perf_counter()
                    solution = qpsolvers.solve_problem(problem, solver=name)
                    seconds = time.perf_counter() - started
                    z = solution.x if solution.found else None
                times.append(seconds)
                if z is None:
                    failures += 1
                else:
                    gaps.append(_gap(_objective(p, z), best))
                    if u0 is not None:
                        diffs.append(float(np.max(np.abs(z[first] - u0))))
            out[name] = _figures(times, gaps, failures, diffs)
        except Exception as exc:  # a backend's own error: reported, not fatal
            message = " ".join(f"{type(exc).__name__}: {exc}".split())
            out[name] = {"error": message[:160]}
    return out


# CasADi's HPIPM interface boxes every variable (nbx = nx, nbu = nu) and replaces an
# infinite bound by a finite one. The QP is scaled (z of order one, see ridempc.mpc.qp), so
# 1e4 stays inactive; with CasADi's default of 1e8, HPIPM ran into its 100-iteration limit
# on some of these problems (none with 1e4, which takes about 7 iterations).
_HPIPM_INF = 1e4


@dataclass(frozen=True)
class _StageLayout:
    """Where the MPC QP's variables and rows go in the OCP layout of CasADi's HPIPM.

    ``columns[j]`` is the MPC index of stage-wise variable ``j``, ``rows[i]`` the MPC row of
    HPIPM constraint row ``i``; ``bound_rows[i]`` is an MPC row with the single entry in
    MPC column ``bound_columns[i]``, passed as a bound on that variable instead.
    """

    horizon: int
    nx: int
    nu: int
    ng: int
    columns: NDArray[np.intp]
    rows: NDArray[np.intp]
    bound_rows: NDArray[np.intp]
    bound_columns: NDArray[np.intp]

    @property
    def options(self) -> dict[str, Any]:
        """CasADi's ``N``, ``nx``, ``nu``, ``ng`` (per stage 0..N; no input at stage N)."""
        n = self.horizon
        return {
            "N": n,
            "nx": [self.nx] * (n + 1),
            "nu": [self.nu] * n + [0],
            "ng": [self.ng] * n + [0],
        }


def _stage_layout(horizon: int, nx: int, nu: int, m: int) -> _StageLayout:
    """Reorder the MPC QP (:mod:`ridempc.mpc.qp`) into the OCP layout of CasADi's HPIPM.

    The MPC orders its variables :math:`z = (x_0, \\dots, x_N, u_0, \\dots, u_{N-1})` and
    its rows as :math:`x_0 = \\hat x_0`, then the dynamics, the input boxes and the
    friction rows :math:`G_k u_k`, each for steps 0..N-1. HPIPM gets, stage by stage:

    - variables :math:`(x_0, u_0, x_1, u_1, \\dots, x_{N-1}, u_{N-1}, x_N)`;
    - rows :math:`[\\mathrm{gap}_0, \\mathrm{lincon}_0, \\dots, \\mathrm{gap}_{N-1},
      \\mathrm{lincon}_{N-1}]`, where :math:`\\mathrm{gap}_k` are the nx dynamics rows of
      step k, :math:`-A_k x_k - B_k u_k + x_{k+1} = c_k` (scaled as the MPC's rows are:
      blocks ``A B I`` with a diagonal
      ``I``, as the interface requires), and :math:`\\mathrm{lincon}_k` the m friction rows
      :math:`g^{lo}_k \\le G_k u_k \\le g^{hi}_k` (blocks ``C = 0``, ``D = G_k``); no
      general rows at stage N;
    - the :math:`x_0` rows and the input boxes, one entry per row, as bounds on the
      variables (``lbx = ubx`` for :math:`x_0`); the other states are unbounded
      (:data:`_HPIPM_INF`).

    So ``N = horizon``, ``nx = [nx] * (N + 1)``, ``nu = [nu] * N + [0]`` and
    ``ng = [m] * N + [0]`` (:attr:`_StageLayout.options`).
    """
    n = horizon
    x_at = np.arange(n + 1)[:, None] * nx + np.arange(nx)  # MPC columns of x_k
    u_at = (n + 1) * nx + np.arange(n)[:, None] * nu + np.arange(nu)  # of u_k
    columns = np.concatenate([np.hstack([x_at[:-1], u_at]).ravel(), x_at[-1]])
    dynamics = nx + np.arange(n)[:, None] * nx + np.arange(nx)
    boxes = nx + n * nx + np.arange(n)[:, None] * nu + np.arange(nu)
    friction = nx + n * (nx + nu) + np.arange(n)[:, None] * m + np.arange(m)
    return _StageLayout(
        horizon=n,
        nx=nx,
        nu=nu,
        ng=m,
        columns=columns,
        rows=np.hstack([dynamics, friction]).ravel(),
        bound_rows=np.concatenate([np.arange(nx), boxes.ravel()]),
        bound_columns=np.concatenate([x_at[0], u_at.ravel()]),
    )


def _solve_hpipm(
    p: sp.csc_matrix,
    a: sp.csc_matrix,
    lower: np.ndarray,
    upper: np.ndarray,
    layout: _StageLayout,
) -> tuple[np.ndarray | None, float]:
    """Solve the MPC QP with HPIPM through CasADi's ``conic`` in the OCP layout of
    :func:`_stage_layout`; the solution in the MPC's order (None if HPIPM fails) and the
    time of the solve call alone [s] (from a cold start).

    Raises:
        ValueError: A row meant as a bound is not one positive entry on its variable.
    """
    import casadi as ca

    columns = layout.columns
    where = np.empty_like(columns)
    where[columns] = np.arange(len(columns))  # MPC column -> stage-wise position
    rows = a.tocsr()[layout.bound_rows]
    if np.any(np.diff(rows.indptr) != 1) or np.any(rows.indices != layout.bound_columns):
        raise ValueError("HPIPM layout: an x_0 or input-box row is not a single entry")
    scale = rows.data
    if np.any(scale <= 0.0):
        raise ValueError("HPIPM layout: an x_0 or input-box row has a non-positive entry")
    n = len(columns)
    lbx, ubx = np.full(n, -np.inf), np.full(n, np.inf)
    lbx[where[layout.bound_columns]] = lower[layout.bound_rows] / scale
    ubx[where[layout.bound_columns]] = upper[layout.bound_rows] / scale
    hessian = ca.DM(p[columns][:, columns].tocsc())
    constraints = ca.DM(a.tocsr()[layout.rows][:, columns].tocsc())
    solver = ca.conic(
        "hpipm",
        "hpipm",
        {"h": hessian.sparsity(), "a": constraints.sparsity()},
        {
            **layout.options,
            "inf": _HPIPM_INF,
            "print_problem": False,
            "hpipm": {"warm_start": False},
            "error_on_fail": False,
        },
    )
    # Clipped here as well as by the option: the runtime in CasADi's source
    # (hpipm_runtime.hpp) clips some of these over another vector's length (ubu over
    # ng_total entries), which would leave infinities in place.
    arguments = {
        "h": hessian,
        "g": np.zeros(n),
        "a": constraints,
        "lba": np.clip(lower[layout.rows], -_HPIPM_INF, _HPIPM_INF),
        "uba": np.clip(upper[layout.rows], -_HPIPM_INF, _HPIPM_INF),
        "lbx": np.clip(lbx, -_HPIPM_INF, _HPIPM_INF),
        "ubx": np.clip(ubx, -_HPIPM_INF, _HPIPM_INF),
    }
    started = time.perf_counter()
    with casadi_solve():
        result = solver(**arguments)
    seconds = time.perf_counter() - started
    if not solver.stats().get("success", False):
        return None, seconds
    z = np.empty(n)
    z[columns] = np.asarray(result["x"]).ravel()
    return z, seconds


def bench_pair(
    robot: str,
    board: str,
    seconds: float = DEFAULT_SECONDS,
    scenario: str | None = None,
    wbc_solver: str = QP_KINDS["wbc"].solver,
    profile: bool = False,
) -> PairBench:
    """Record one pair's ride and time its problems (see the module docstring), with
    ``wbc_solver`` solving the whole-body QPs in the ride and in their timing; with
    ``profile``, ride again under :class:`~ridempc.tickprofile.PartProfiler` for the
    hottest functions of each part of the tick."""
    from ridempc.mpc.controller import LinearMpc

    name = f"{robot}-{board}"
    out = PairBench(pair=name, scenario=_scenario_of(name, scenario), wbc_solver=wbc_solver)
    out.reference_ms = reference_ms()
    result, problems, wbc_inputs, rider, budget = _record(
        robot, board, out.scenario, seconds, wbc_solver
    )
    out.budget_ms = budget
    out.ride_status = "fell" if result.fell else result.status
    out.simulated_s = float(result.sim_time)
    loop = result.wall_time  # the loop's own, without building the scene
    out.real_time_factor = float(result.sim_time / loop) if loop > 0 else float("nan")
    out.mpc_problems, out.wbc_ticks = len(problems), len(wbc_inputs)
    out.mpc_tick_median_ms, out.mpc_tick_p99_ms = _stats([1e-3 * ms for ms in rider.mpc_tick_ms])
    out.controller_tick_p99_ms = _stats(result.controller_times.tolist())[1]
    out.controller_physics_ratio = _controller_physics_ratio(result)
    out.tick_phases_ms = _tick_phases(rider, result.controller_times)
    cpu = result.cpu_time  # the loop's thread's own: what the machine's load adds least to
    out.cpu_real_time_factor = float(result.sim_time / cpu) if cpu > 0 else float("nan")
    out.tick_phases_cpu_ms = _tick_phases(rider, result.controller_cpu_times)
    if profile:
        profiler = PartProfiler(BUDGET_PARTS, TICK_KINDS)
        profiled = _record(robot, board, out.scenario, seconds, wbc_solver, profiler)[0]
        out.profile = profiler.hottest(len(profiled.controller_times), DEFAULT_TOP)
        out.profile_by_tick = profiler.hottest_by_kind(DEFAULT_TOP)
    if problems:
        mpc = LinearMpc(rider.pair, rider.mpc.reference, rider.mpc.model, rider.mpc.settings)
        times, qp, first_inputs = _mpc_pass(mpc, problems)
        passes = [times] + [_mpc_pass(mpc, problems)[0] for _ in range(PASSES - 1)]
        out.mpc_solve_median_ms, out.mpc_solve_p99_ms = _stats(times)
        out.mpc_solve_best_p99_ms = _best_p99(passes)
        out.solvers = _other_solvers(qp, problems)
        out.solvers["osqp"] = {**_figures(times, [0.0], int(qp.failures)), "warm_started": True}
        out.solvers[OSQP_BOUNDS_CLASSES] = _classes_by_bounds(mpc, problems, first_inputs)
    if wbc_inputs:
        times, solved, out.wbc_failures = _wbc_pass(rider, wbc_inputs)
        passes = [times] + [_wbc_pass(rider, wbc_inputs)[0] for _ in range(PASSES - 1)]
        out.wbc_solve_median_ms, out.wbc_solve_p99_ms = _stats(times)
        out.wbc_solve_best_p99_ms = _best_p99(passes)
        out.wbc_solvers = _other_wbc_solvers(rider, solved, wbc_solver)
    return out


def _tick_phases(rider: Any, seconds: Any) -> dict[str, float]:
    """The controller ticks by their place in the MPC's period
    (:func:`~ridempc.tickphases.tick_phases`): the MPC's tick, the plan's take-up (its own
    tick from a ``plan_latency`` of one on) and the backup's standby, after the ride's
    first :data:`~ridempc.mpc.rider.STANDBY_WARMUP_S` (the standby there runs every tick)."""
    from ridempc.mpc.rider import MPC_DIVIDER, STANDBY_WARMUP_S

    handover = rider.handover
    periodic = {
        "mpc_tick": 0,
        "take_up": rider.plan_latency or None,
        "standby": handover.standby_phase if handover.standby_every == MPC_DIVIDER else None,
    }
    return tick_phases(seconds, MPC_DIVIDER, periodic, rider.rate_hz, STANDBY_WARMUP_S)


def _controller_physics_ratio(result: Any) -> float:
    """The rider's wall time over the simulation's (physics, sensors, firmware, log) in
    the same ride [-]."""
    rider = float(np.sum(result.controller_times))
    physics = result.wall_time - rider
    return rider / physics if physics > 0.0 else float("nan")


def _best_p99(passes: Sequence[Sequence[float]]) -> float:
    """The p99 [ms] of each problem's fastest pass (times in seconds, a list per pass)."""
    return _stats(np.min(passes, axis=0).tolist())[1]


def _mpc_pass(mpc: Any, problems: list, **osqp: Any) -> tuple[list[float], Any, Any]:
    """The recorded MPC problems solved in order by a fresh QP (the same warm starts, the
    same work in every pass; ``osqp`` over its settings): each solve's wall time [s], the
    QP, and the plans' first inputs in units of their tolerances (one row per problem)."""
    qp = mpc.build_qp(problems[0], **osqp)
    times, first_inputs = [], []
    with frozen_heap():  # the recorded problems are not the controller's to collect
        for problem in problems:
            started = time.perf_counter()
            plan = qp.solve(problem)
            times.append(time.perf_counter() - started)
            first_inputs.append(plan.first_input)
    return times, qp, np.asarray(first_inputs) / qp._input_scale


def _classes_by_bounds(mpc: Any, problems: list, first_inputs: Any) -> dict[str, Any]:
    """OSQP warm-started as :func:`_mpc_pass` with each row in the class its bounds give it
    (:mod:`~ridempc.mpc.row_classes` off): its times, and the largest difference of its
    first inputs from the loop's QP's [tolerances]."""
    times, qp, inputs = _mpc_pass(mpc, problems, row_classes=False)
    diffs = np.max(np.abs(inputs - first_inputs), axis=1).tolist()
    return {**_figures(times, [0.0], int(qp.failures), diffs), "warm_started": True}


def _wbc_copy(rider: Any, solver: str | None = None) -> Any:
    """A fresh copy of the rider's WBC (its settings, its rolling platforms), on
    ``solver`` if given."""
    from dataclasses import replace

    from ridempc.wbc import WholeBodyController

    settings = rider.wbc.settings if solver is None else replace(rider.wbc.settings, solver=solver)
    return WholeBodyController(
        rider.robot, settings, pinocchio=rider.pinocchio, platforms=rider.wbc.platforms
    )


def _wbc_pass(rider: Any, inputs: list) -> tuple[list[float], list, int]:
    """The recorded whole-body ticks solved in order by a fresh copy of the rider's WBC:
    each tick's wall time [s], the solved QPs (problem, solution, the QP's time [s]) and the
    number of ticks that failed."""
    wbc = _wbc_copy(rider)
    times, solved, failures = [], [], 0
    with frozen_heap():
        for state, targets in inputs:
            started = time.perf_counter()
            try:
                output = wbc.solve(state, targets)
            except RidempcError:  # a tick of a ride that was falling: timed, counted
                failures += 1
            else:
                assert wbc.last_problem is not None and wbc.last_solution is not None
                solved.append((wbc.last_problem, wbc.last_solution.x, 1e-3 * output.solve_ms))
            times.append(time.perf_counter() - started)
    return times, solved, failures


def _osqp_workspace(rider: Any, solved: list) -> tuple[list[float], list, int]:
    """The solved QPs in order in a fresh copy of the rider's OSQP workspace (warm-started
    from one to the next): each solve's time [s], its solution (None: failed), failures."""
    qp = _wbc_copy(rider, "osqp").qp
    times: list[float] = []
    answers: list[np.ndarray | None] = []
    failures = 0
    with frozen_heap():
        for problem, _, _ in solved:
            try:
                solution = qp.solve(problem)
            except RidempcError:
                failures += 1
                answers.append(None)
                continue
            times.append(solution.solve_time)
            answers.append(solution.x)
    return times, answers, failures


def _other_wbc_solvers(rider: Any, solved: list, in_loop: str) -> dict[str, dict[str, Any]]:
    """The loop's WBC solves (``in_loop``'s) against the other solvers' on the same
    problems (module docstring): OSQP in its warm workspace, the others from a cold start;
    ``solved`` holds (problem, the loop solver's solution, its QP time [s])."""
    import qpsolvers

    kind = QP_KINDS["wbc"]
    torque = rider.wbc.qp.layout.torque
    out = {in_loop: {**_figures([t for _, _, t in solved], [0.0], 0), "warm_started": False}}
    for name in (*kind.solvers, *kind.compared):
        installed = name in kind.solvers or name in qpsolvers.available_solvers
        if name == in_loop or not installed:
            continue
        times: list[float] = []
        answers: list[np.ndarray | None] = []
        failures = 0
        if name == "osqp":
            times, answers, failures = _osqp_workspace(rider, solved)
        else:
            for problem, _, _ in solved:
                answer = solve_dense(name, problem)
                times.append(answer.seconds)
                answers.append(answer.x)
                failures += int(answer.x is None)
        pairs = [(p, x, z) for (p, x, _), z in zip(solved, answers, strict=True) if z is not None]
        gaps = [_gap(_objective(p.P, z, p.q), _objective(p.P, x, p.q)) for p, x, z in pairs]
        diffs = [float(np.max(np.abs(z[torque] - x[torque]))) for _, x, z in pairs]
        figures = _figures(times, gaps, failures, diffs)
        out[name] = {**figures, "warm_started": name == "osqp"}
    out[in_loop]["warm_started"] = in_loop == "osqp"
    return out


def _ms(v: float) -> str:
    """A figure for the tables, '-' when NaN."""
    return "-" if v != v else f"{v:.2f}"


def bench_table(rows: Sequence[PairBench]) -> str:
    """The results as a Markdown table, then one table each of the MPC and WBC QP solvers."""

    lines = [
        "| pair | scenario | ride | MPC problems | MPC QP median / p99 / best p99 [ms] | "
        "MPC tick in the ride median / p99 [ms] | WBC ticks (failed) | "
        "WBC (solver) median / p99 / best p99 [ms] | controller tick p99 [ms] | "
        "controller / physics | real-time factor |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        mpc = (r.mpc_solve_median_ms, r.mpc_solve_p99_ms, r.mpc_solve_best_p99_ms)
        wbc = (r.wbc_solve_median_ms, r.wbc_solve_p99_ms, r.wbc_solve_best_p99_ms)
        lines.append(
            f"| {r.pair} | {r.scenario} | {r.ride_status} ({r.simulated_s:.2f} s) | "
            f"{r.mpc_problems} | {' / '.join(map(_ms, mpc))} | "
            f"{_ms(r.mpc_tick_median_ms)} / {_ms(r.mpc_tick_p99_ms)} | "
            f"{r.wbc_ticks} ({r.wbc_failures}) | "
            f"({r.wbc_solver}) {' / '.join(map(_ms, wbc))} | "
            f"{_ms(r.controller_tick_p99_ms)} | {_ms(r.controller_physics_ratio)} | "
            f"{_ms(r.real_time_factor)} |"
        )
    lines += _budget_table(rows)
    for what, table in (("MPC", "solvers"), ("WBC", "wbc_solvers")):
        lines += _solver_table(what, [(r.pair, getattr(r, table)) for r in rows])
    profiled = [(r.pair, r.profile) for r in rows if r.profile]
    if profiled:
        lines += profile_table(profiled)
        by_tick = [(r.pair, r.profile_by_tick) for r in rows if r.profile_by_tick]
        lines += profile_table(by_tick, by="tick")
    return "\n".join(lines)


def _budget_table(rows: Sequence[PairBench]) -> list[str]:
    """The closed loop's budget: mean wall time per 2 ms control tick [ms], by part; the
    periodic ticks' medians and the other ticks' p99 (:mod:`ridempc.tickphases`)."""
    head = " | ".join(BUDGET_PARTS)
    lines = [
        "",
        f"| pair | mean per control tick [ms]: loop | {head} | machine reference [ms] | "
        "median tick [ms]: MPC / take-up / standby | other ticks' p99 [ms] | "
        "loop's CPU: real-time factor; median tick [ms] MPC / take-up / standby / other |",
    ]
    lines.append("|---|---|" + "---|" * len(BUDGET_PARTS) + "---|---|---|---|")
    for r in rows:
        b, phases = r.budget_ms, r.tick_phases_ms
        cells = " | ".join(_ms(b.get(k, float("nan"))) for k in ("loop", *BUDGET_PARTS))
        steady = _ms(phases.get("steady_p99", float("nan")))
        cpu = f"{r.cpu_real_time_factor:.2f}; {_periodic(r.tick_phases_cpu_ms, 'steady_median')}"
        lines.append(
            f"| {r.pair} | {cells} | {_ms(r.reference_ms)} | {_periodic(phases)} | {steady} | "
            f"{cpu} |"
        )
    return lines


def _periodic(phases: dict[str, float], *more: str) -> str:
    """The periodic ticks' medians [ms] (and ``more`` figures), ``/``-separated."""
    keys = [f"{k}_median" for k in ("mpc_tick", "take_up", "standby")] + list(more)
    return " / ".join(_ms(phases.get(k, float("nan"))) for k in keys)


def _solver_table(what: str, rows: Sequence[tuple[str, dict[str, dict[str, Any]]]]) -> list[str]:
    """One solver table: per pair and solver, median / p99 [ms], failures, largest
    objective gap and largest difference in the first input (:func:`_figures`)."""
    unit = "u_0 [tolerances]" if what == "MPC" else "torque [N m]"
    lines = [
        "",
        f"| pair | {what} QP solver | median / p99 [ms] | failures | max objective gap | "
        f"max first-input difference, {unit} |",
    ]
    lines.append("|---|---|---|---|---|---|")
    for pair, solvers in rows:
        for name, s in solvers.items():
            if "error" in s:
                lines.append(f"| {pair} | {name} | {s['error']} | - | - | - |")
                continue
            gap, diff = s["objective_gap_max"], s.get("first_input_diff_max")
            lines.append(
                f"| {pair} | {name} | {_ms(s['solve_median_ms'])} / {_ms(s['solve_p99_ms'])} | "
                f"{s['failures']} | {'-' if gap is None else f'{gap:.1e}'} | "
                f"{'-' if diff is None else f'{diff:.1e}'} |"
            )
    return lines


def bench(
    pairs: Sequence[str] | None = None,
    seconds: float = DEFAULT_SECONDS,
    json_path: Path | None = None,
    scenario: str | None = None,
    wbc_solver: str | None = None,
    profile: bool = False,
) -> list[PairBench]:
    """Benchmark ``pairs`` (default: every pair with an MPC) on their pair files'
    ``bench_scenario`` (or ``scenario`` for all), with ``wbc_solver`` in the
    whole-body QP, print and optionally save; with ``profile``, each pair's hottest
    functions per part of the tick too.

    Raises:
        UnknownNameError: A pair without an MPC, an unknown scenario or an unknown
            ``wbc_solver``.
        ConfigError: ``scenario`` has no version for one of the pairs' boards.
    """
    from dataclasses import asdict

    from ridempc.errors import UnknownNameError
    from ridempc.mpc.pairs import mpc_pair_names

    kind = QP_KINDS["wbc"]
    wbc_solver = kind.solver if wbc_solver is None else wbc_solver
    if wbc_solver not in kind.solvers:
        raise UnknownNameError("whole-body QP solver", wbc_solver, kind.solvers)
    names = list(pairs) if pairs else list(mpc_pair_names())
    for name in names:
        if name not in mpc_pair_names():
            raise UnknownNameError("robot-board pair for the MPC", name, mpc_pair_names())
    from ridempc.scenarios import resolve_scenario

    recorded = {n: _scenario_of(n, scenario) for n in names}
    for name in names:  # every scenario checked before the first ride
        resolve_scenario(recorded[name], name.split("-", 1)[1])
    rows = []
    for name in names:
        robot, board = name.split("-", 1)
        print(f"  {name}: recording {seconds:g} s of {recorded[name]} ...", flush=True)
        rows.append(bench_pair(robot, board, seconds, recorded[name], wbc_solver, profile))
    print(bench_table(rows))
    if json_path is not None:

        def clean(value: Any) -> Any:
            if isinstance(value, float) and value != value:
                return None
            if isinstance(value, dict):
                return {k: clean(v) for k, v in value.items()}
            return value

        atomic_write_json(json_path, {r.pair: clean(asdict(r)) for r in rows})
    return rows
