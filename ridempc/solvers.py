"""The QP solvers by name: which solver each of the controller's QPs runs on, and the
others ``ridempc bench`` compares it with.

Each kind of QP (:data:`QP_KINDS`) names the solver measured fastest on its recorded
problems (:attr:`QpKind.solver`), the solvers the controller can run it on
(:attr:`QpKind.solvers`, e.g. ``ridempc bench --wbc-solver osqp`` to measure the choice in
the closed loop) and the ones the bench only compares (:attr:`QpKind.compared`). The MPC,
the whole-body controller and the bench all ask here (:func:`solver_for`). The MPC's QP
also names its rescue solver (:attr:`QpKind.rescue`): the interior point method that
solves its elastic form when OSQP gives no plan (:mod:`ridempc.mpc.elastic`).

Dense QPs :math:`\\min \\tfrac12 z^\\top P z + q^\\top z`, :math:`l \\le A z \\le u`
(:class:`DenseQp`, the whole-body QP) go to a backend by name through
:func:`solve_dense`: DAQP directly (an exact dual active-set method, Arnström et al.
2022; rows with :math:`l = u` as equalities), any other through qpsolvers. OSQP, with
its persistent warm-started workspace, is the QPs' own code
(:class:`~ridempc.mpc.qp.MpcQP`, :class:`~ridempc.wbc.qp.WholeBodyQP`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from types import MappingProxyType
from typing import NamedTuple, Protocol

import daqp
import numpy as np
from numpy.typing import NDArray

from ridempc.errors import UnknownNameError

__all__ = [
    "DAQP_INFINITY",
    "QP_KINDS",
    "DenseQp",
    "DenseSolution",
    "QpKind",
    "solve_daqp",
    "solve_dense",
    "solver_for",
]

Array = NDArray[np.float64]
DAQP_INFINITY: float = 1e30  # DAQP's bound for a free row


@dataclass(frozen=True)
class QpKind:
    """One kind of QP and its solvers.

    Attributes:
        name: The QP's name (``mpc``, ``wbc``).
        solver: The solver it runs on: the fastest on its recorded problems.
        solvers: Those the controller can run it on.
        compared: Those ``ridempc bench`` times on its recorded problems besides.
        rescue: The solver of its elastic form when its own gives no plan
            (:mod:`ridempc.mpc.elastic`; None: none).
    """

    name: str
    solver: str
    solvers: tuple[str, ...]
    compared: tuple[str, ...]
    rescue: str | None = None


# Measured by ``ridempc bench`` (cassie-hovershoes, velocity-steps, 3 s, machine reference
# 22 ms), median / p99 of each solve [ms]. The MPC's sparse QP (12 steps): OSQP warm-started
# in its workspace 1.13 / 1.32, HPIPM from a cold start 2.09 / 3.20, proxqp 4.50 / 4.90,
# DAQP (dense) 14.3 / 18.9. The whole-body QP (dense, 56 variables): DAQP 0.04 / 0.08 to
# the same optimum (objective within 2e-15), OSQP warm-started 0.21 / 0.28, proxqp
# 0.23 / 0.39. docs/tuning.md, "Speed (issue 39): solvers and the MPC tick". On the four
# pairs' recorded MPC problems (CPU clock) OSQP warm-started is the fastest, the next (HPIPM
# or PIQP from a cold start) at 1.9-2.3x its median (docs/tuning.md, "The MPC's QP rows held
# in one OSQP class ...").
QP_KINDS: MappingProxyType[str, QpKind] = MappingProxyType(
    {
        "mpc": QpKind(
            "mpc",
            solver="osqp",
            solvers=("osqp",),
            compared=("proxqp", "daqp", "piqp", "clarabel", "hpipm (casadi)"),
            rescue="piqp",  # interior point: 13-15 iterations where OSQP's budget ran out
        ),
        "wbc": QpKind("wbc", solver="daqp", solvers=("daqp", "osqp"), compared=("proxqp",)),
    }
)


def solver_for(kind: str, name: str | None = None) -> str:
    """The solver of the QP ``kind``: ``name`` if given (checked), else the kind's own.

    Raises:
        UnknownNameError: An unknown kind, or a solver the kind cannot run on.
    """
    if kind not in QP_KINDS:
        raise UnknownNameError("QP kind", kind, tuple(QP_KINDS))
    entry = QP_KINDS[kind]
    if name is None:
        return entry.solver
    if name not in entry.solvers:
        raise UnknownNameError(f"{kind} QP solver", name, entry.solvers)
    return name


class DenseQp(Protocol):
    """A dense QP: :math:`\\min \\tfrac12 z^\\top P z + q^\\top z`, :math:`l \\le A z \\le u`
    (``inf`` where a row is free)."""

    @property
    def P(self) -> Array: ...  # noqa: N802 - the QP's usual name

    @property
    def q(self) -> Array: ...

    @property
    def A(self) -> Array: ...  # noqa: N802 - the QP's usual name

    @property
    def l(self) -> Array: ...  # noqa: E743 - the QP's usual name

    @property
    def u(self) -> Array: ...


class DenseSolution(NamedTuple):
    """A dense backend's answer.

    Attributes:
        x: The solution (None if none was found).
        found: Whether the backend solved the QP.
        flag: The backend's exit flag (DAQP's: 1 or more solved; others: 1 or 0).
        iterations: Its iterations (0 where it does not say).
        duals: The row multipliers (None where it does not say).
        seconds: The solve call's wall time [s].
    """

    x: Array | None
    found: bool
    flag: int
    iterations: int
    duals: Array | None
    seconds: float


def solve_daqp(problem: DenseQp) -> tuple[Array, int, int, Array]:
    """DAQP on the dense problem, rows with :math:`l = u` as equalities.

    Returns:
        The solution, DAQP's exit flag (1 or more: solved), its iterations and the row
        multipliers.
    """
    equal = problem.l == problem.u
    sense = np.where(equal, 5, 0).astype(np.int32)  # 5: an equality (active, immutable)
    upper = np.where(np.isfinite(problem.u), problem.u, DAQP_INFINITY)
    lower = np.where(np.isfinite(problem.l), problem.l, -DAQP_INFINITY)
    x, _, flag, info = daqp.solve(
        np.ascontiguousarray(problem.P, dtype=float),
        np.array(problem.q, dtype=float),
        np.ascontiguousarray(problem.A, dtype=float),
        upper,
        lower,
        sense,
    )
    return (
        np.asarray(x, dtype=float),
        int(flag),
        int(info["iterations"]),
        np.asarray(info["lam"], dtype=float),
    )


def _qpsolvers(name: str, problem: DenseQp) -> DenseSolution:
    """``name`` through qpsolvers, rows with :math:`l = u` as equalities."""
    import qpsolvers

    equal = problem.l == problem.u
    upper = ~equal & np.isfinite(problem.u)
    lower = ~equal & np.isfinite(problem.l)
    qp = qpsolvers.Problem(
        P=problem.P,
        q=problem.q,
        G=np.vstack([problem.A[upper], -problem.A[lower]]),
        h=np.concatenate([problem.u[upper], -problem.l[lower]]),
        A=problem.A[equal],
        b=problem.l[equal],
    )
    started = time.perf_counter()
    solution = qpsolvers.solve_problem(qp, solver=name)
    seconds = time.perf_counter() - started
    found = bool(solution.found) and solution.x is not None
    x = np.asarray(solution.x, dtype=float) if found else None
    return DenseSolution(x, found, int(found), 0, None, seconds)


def solve_dense(name: str, problem: DenseQp) -> DenseSolution:
    """``problem`` solved by the backend ``name`` from a cold start (module docstring).

    Raises:
        UnknownNameError: ``name`` is neither DAQP nor a qpsolvers backend installed here.
    """
    if name == "daqp":
        started = time.perf_counter()
        x, flag, iterations, duals = solve_daqp(problem)
        seconds = time.perf_counter() - started
        found = flag >= 1 and bool(np.all(np.isfinite(x)))
        return DenseSolution(x if found else None, found, flag, iterations, duals, seconds)
    import qpsolvers

    if name not in qpsolvers.available_solvers:
        raise UnknownNameError("dense QP solver", name, ("daqp", *qpsolvers.available_solvers))
    return _qpsolvers(name, problem)
