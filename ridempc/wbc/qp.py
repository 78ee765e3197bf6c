"""The whole-body QP: build its matrices from tasks and constraints, solve them by name.

.. math:: \\min_z \\tfrac12 z^\\top P z + q^\\top z \\quad \\text{s.t.} \\quad l \\le A z \\le u,
          \\qquad P = \\sum_i H_i, \\quad q = \\sum_i c_i

(:mod:`ridempc.wbc.tasks`, :mod:`ridempc.wbc.constraints`). :meth:`WholeBodyQP.build` makes
the dense matrices (:class:`QpProblem`, testable without a solver); :meth:`WholeBodyQP.solve`
hands them to one persistent OSQP workspace (:mod:`ridempc.wbc.workspace`).

**Fixed sparsity, dense assembly.** The problem is small (42 variables and 62 rows for the
quadruped, 56 and 74 for Cassie), so the tasks and constraints are assembled as dense NumPy
blocks; but OSQP factors its KKT matrix at every matrix update, and there the sparsity
matters (Cassie's legs do not couple in :math:`M`, the contact Jacobians touch one leg each,
the force and torque blocks are diagonal): the pattern keeps 195 of the 903 entries of the
quadruped's upper :math:`P` and 510 of the 2604 of its :math:`A` (Cassie: 439 of 1596, 988
of 4144). So the workspace is set up once with a fixed pattern, the union of the non-zeros
of probe problems at a generic configuration, and each tick only its values are copied in
(``update(Px=..., Ax=...)``), with the previous primal and dual solution as the warm
start. A value that falls outside the pattern (a configuration never seen) widens the
pattern and sets the workspace up again (counted in :attr:`WholeBodyQP.setups`), so the
pattern is a speed-up, never a source of error.

**Exact equalities.** OSQP's polishing solves the identified active set exactly, so the
dynamics hold to ~1e-12 though ADMM stops at 1e-4; where polishing fails (a degenerate
active set), :meth:`WholeBodyQP._refine` projects the solution onto its active rows.

**A second solver.** Where OSQP fails even from a cold start, the same dense problem goes
to DAQP (an exact dual active-set solver, Arnström et al. 2022), counted in
:attr:`WholeBodyQP.fallbacks`. ADMM converges slowly on an ill-conditioned :math:`P`: the
dog's QP in a push-off, with eigenvalues from 1e-5 to 100, ran out of 2000 iterations
warm and cold, and DAQP solved it to 1e-12 in 0.2 ms.

**Or DAQP alone, the registry's choice.** The solver is named in :attr:`WbcSettings.solver
<ridempc.wbc.settings.WbcSettings>`, by default the one :data:`ridempc.solvers.QP_KINDS`
measured fastest on the recorded problems: DAQP, to which every problem then goes straight
(:func:`ridempc.solvers.solve_dense`); ``solver="osqp"`` takes the workspace above, so that
``ridempc bench --wbc-solver osqp`` measures the choice in the closed loop.

**Always a command.** Where every solver finds the problem infeasible, its soft rows are
given a slack (:mod:`ridempc.wbc.elastic`), the dynamics and the torque limits kept, and
that problem, which always has a solution, goes to DAQP; the slack is recorded in the
solution (:attr:`QpSolution.slack`) and the solves counted (:attr:`WholeBodyQP.elastic_solves`).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sparse
from numpy.typing import NDArray

from ridempc.errors import RidempcError
from ridempc.solvers import solve_daqp, solve_dense, solver_for
from ridempc.wbc.constraints import Constraint, LinearConstraint
from ridempc.wbc.contacts import ContactSet
from ridempc.wbc.elastic import elastic_problem, solve_elastic
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.model import ModelTerms
from ridempc.wbc.settings import DEFAULT_OSQP_SETTINGS
from ridempc.wbc.targets import WbcTargets
from ridempc.wbc.tasks import Objective, Task
from ridempc.wbc.workspace import OsqpResult, OsqpWorkspace

__all__ = ["QpProblem", "QpSolution", "WbcFailed", "WholeBodyQP", "solve_daqp"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
ACCEPTED: frozenset[str] = frozenset({"solved", "solved inaccurate"})
PATTERN_TOLERANCE: float = 1e-12  # [-] entries dropped from the pattern, over the largest


@dataclass(frozen=True)
class QpProblem:
    """One tick's QP, dense: :math:`\\min \\tfrac12 z^\\top P z + q^\\top z`,
    :math:`l \\le A z \\le u` (``inf`` bounds where a row is free).

    Attributes:
        P: Objective Hessian, symmetric, (n, n).
        q: Objective gradient, (n,).
        A: Constraint matrix, (m, n).
        l: Lower bounds, (m,).
        u: Upper bounds, (m,).
        build_time: Time to build it [s].
    """

    P: Array
    q: Array
    A: Array
    l: Array  # noqa: E741 - the QP's usual name
    u: Array
    build_time: float = 0.0


@dataclass(frozen=True)
class QpSolution:
    """OSQP's answer.

    Attributes:
        x: Primal solution :math:`z`.
        y: Dual solution (one multiplier per row of :math:`A`).
        status: OSQP's status string.
        iterations: ADMM iterations.
        polished: Whether OSQP's polishing succeeded (active set solved exactly).
        refined: Whether, polishing having failed, :meth:`WholeBodyQP._refine` moved the
            solution onto its active set.
        solve_time: Update of the workspace, factorisation and solve, wall clock [s].
        osqp_time: OSQP's own run time (factorisation, iterations, polish) [s].
        slack: The largest slack the soft rows took (0 where the problem was solved as
            it is), in its row's units [m/s^2 or N].
    """

    x: Array
    y: Array
    status: str
    iterations: int
    polished: bool
    refined: bool
    solve_time: float
    osqp_time: float
    slack: float = 0.0


def _violation(problem: QpProblem, ax: Array) -> float:
    """Largest distance of :math:`A z` outside :math:`[l, u]`."""
    return float(np.max(np.maximum(ax - problem.u, problem.l - ax), initial=0.0))


class WbcFailed(RidempcError, RuntimeError):
    """The whole-body QP has no acceptable solution.

    Attributes:
        status: OSQP's status (e.g. ``primal infeasible``, ``maximum iterations reached``),
            or None where DAQP was the solver (``solver="daqp"``).
        problem: The problem that failed.
        daqp_flag: DAQP's exit flag, if it was tried (negative: infeasible or failed).
    """

    def __init__(
        self, status: str | None, problem: QpProblem, daqp_flag: int | None = None
    ) -> None:
        self.status = status
        self.problem = problem
        self.daqp_flag = daqp_flag
        if status is None:  # DAQP was the solver, not OSQP's second
            what = f"DAQP exit flag {daqp_flag}"
        else:
            second = "" if daqp_flag is None else f", DAQP exit flag {daqp_flag}"
            what = f"OSQP status '{status}' (accepted: {', '.join(sorted(ACCEPTED))}){second}"
        super().__init__(
            f"whole-body QP failed: {what}; {problem.A.shape[0]} rows, "
            f"{problem.A.shape[1]} variables"
        )


class _Pattern:
    """A fixed CSC pattern over a dense matrix: the flat indices that fill it, in CSC order,
    and those of the entries it leaves out (for a symmetric matrix, of its upper triangle).

    Args:
        mask: Where the pattern has entries (upper triangular for ``upper``).
        upper: The dense matrix is symmetric and only its upper triangle is kept.
    """

    def __init__(self, mask: NDArray[np.bool_], upper: bool = False) -> None:
        cols, rows = np.nonzero(mask.T)  # column-major order: CSC
        self.shape = mask.shape
        self.rows = rows.astype(np.int64)
        self.flat: Index = (rows * mask.shape[1] + cols).astype(np.int64)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=mask.shape[1]))])
        region = np.triu(np.ones(mask.shape, dtype=bool)) if upper else np.ones_like(mask)
        self.outside: Index = np.flatnonzero(region & ~mask)

    def values(self, dense: Array) -> Array:
        return np.asarray(dense.take(self.flat))  # take: faster than fancy indexing

    def csc(self, dense: Array) -> sparse.csc_matrix:
        return sparse.csc_matrix((self.values(dense), self.rows, self.indptr), shape=self.shape)


class WholeBodyQP:
    """Builds and solves the whole-body QP in one persistent, warm-started OSQP workspace.

    Args:
        layout: The decision vector's layout.
        tasks: The objective's terms.
        constraints: The constraint blocks.
        settings: OSQP settings (``DEFAULT_OSQP_SETTINGS`` where not given).
        solver: ``osqp`` (module docstring), or a dense backend of
            :func:`~ridempc.solvers.solve_dense` (``daqp``): each problem straight to it,
            no OSQP workspace; None: the registry's (:data:`~ridempc.solvers.QP_KINDS`).

    Attributes:
        setups: OSQP workspace set-ups so far (one at the first solve, one more each time
            the pattern had to widen, or after a failed solve, which restarts cold).
        cold_retries: Warm-started solves that failed and were retried cold.
        fallbacks: Solves OSQP failed and DAQP answered.
        elastic_solves: Solves that needed slack on the soft rows (module docstring).
        last: The last solution, or None.
    """

    def __init__(
        self,
        layout: DecisionLayout,
        tasks: Sequence[Task],
        constraints: Sequence[Constraint],
        settings: Mapping[str, float | int | bool] | None = None,
        solver: str | None = None,
    ) -> None:
        self.layout = layout
        self.solver = solver_for("wbc", solver)
        self.tasks = tuple(tasks)
        self.constraints = tuple(c for c in constraints if c.rows > 0)
        self.settings = {**DEFAULT_OSQP_SETTINGS, **(settings or {})}
        self.rows = sum(c.rows for c in self.constraints)
        # per row: whether it may take a slack (ridempc.wbc.elastic)
        self.soft = np.repeat(
            [c.soft for c in self.constraints], [c.rows for c in self.constraints]
        )
        ends = np.cumsum([0] + [c.rows for c in self.constraints])
        self._row_slices = tuple(slice(a, b) for a, b in zip(ends[:-1], ends[1:], strict=True))
        n = layout.size
        self._p_mask = np.eye(n, dtype=bool)
        self._a_mask = np.zeros((self.rows, n), dtype=bool)
        self._p: _Pattern | None = None
        self._a: _Pattern | None = None
        self._solver: OsqpWorkspace | None = None
        self.setups = 0
        self.cold_retries = 0
        self.fallbacks = 0
        self.elastic_solves = 0
        self.last: QpSolution | None = None

    # ----------------------------------------------------------------- build

    def build(self, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet) -> QpProblem:
        """The dense QP of one tick (no solver involved)."""
        start = time.perf_counter()
        n = self.layout.size
        hessian = np.zeros((n, n))
        gradient = np.zeros(n)
        objective = Objective(hessian, gradient)
        for task in self.tasks:
            task.add_qp_objective(objective, terms, targets, contacts)
        matrix = np.zeros((self.rows, n))
        lower, upper = np.empty(self.rows), np.empty(self.rows)
        for constraint, rows in zip(self.constraints, self._row_slices, strict=True):
            block = LinearConstraint(matrix[rows], lower[rows], upper[rows])  # views
            constraint.fill_qp_constraint(block, terms, targets, contacts)
        return QpProblem(
            hessian, gradient, matrix, lower, upper, build_time=time.perf_counter() - start
        )

    def include_pattern(self, problem: QpProblem) -> None:
        """Widen the fixed pattern by ``problem``'s non-zeros (e.g. a probe problem at a
        generic configuration, before the first tick)."""
        self._p_mask |= np.triu(problem.P != 0.0)
        self._a_mask |= problem.A != 0.0
        self._solver = None

    # ----------------------------------------------------------------- solve

    def solve(self, problem: QpProblem) -> QpSolution:
        """Solve ``problem`` as it is, or where it has no solution, with slack on its soft
        rows (module docstring).

        Raises:
            WbcFailed: Neither finds a finite solution (the elastic problem always has
                one: a backend's numerical failure).
        """
        start = time.perf_counter()
        try:
            return self._solve_hard(problem, start)
        except WbcFailed as failed:
            return self._solve_elastic(problem, failed, start)

    def _solve_elastic(self, problem: QpProblem, failed: WbcFailed, start: float) -> QpSolution:
        """``problem`` with slack on its soft rows, by DAQP.

        Raises:
            WbcFailed: ``failed``, where DAQP finds no solution to it either.
        """
        elastic = elastic_problem(problem.P, problem.q, problem.A, problem.l, problem.u, self.soft)
        x, slack, answer = solve_elastic(elastic)
        if not answer.found:
            raise failed
        self.elastic_solves += 1
        duals = answer.duals if answer.duals is not None else np.zeros(len(problem.l))
        solution = QpSolution(
            x=x,
            y=duals,
            status="solved with slack",
            iterations=answer.iterations,
            polished=True,
            refined=False,
            solve_time=time.perf_counter() - start,
            osqp_time=0.0,
            slack=float(np.max(np.abs(slack), initial=0.0)),
        )
        self.last = solution
        return solution

    def _solve_hard(self, problem: QpProblem, start: float) -> QpSolution:
        """Solve ``problem`` in the persistent workspace, or by the dense backend.

        Raises:
            WbcFailed: OSQP's status is not ``solved`` or ``solved inaccurate``, or the
                solution is not finite (after a retry from a cold start, if it was warm),
                and DAQP finds no solution either.
        """
        if self.solver != "osqp":
            return self._dense(problem, start)
        solver = self._solver
        warm = solver is not None and self._fits(problem)
        if warm:
            assert solver is not None and self._p is not None and self._a is not None
            solver.update(
                problem.q,
                problem.l,
                problem.u,
                self._p.values(problem.P),
                self._a.values(problem.A),
            )
        else:
            solver = self._setup(problem)
        result = solver.solve()
        accepted = self._accepted(result)
        if warm and not accepted:
            # A warm start (iterates and adapted rho of the last tick) can stall where a
            # cold one converges: Cassie on the Segway at 3.854 s ran out of 2000 iterations
            # warm and solved in 1050 cold. Retry once from scratch.
            self.cold_retries += 1
            solver = self._setup(problem)
            result = solver.solve()
            accepted = self._accepted(result)
        if not accepted:
            self._solver = None  # its iterates would warm-start the next tick from garbage
            return self._second_solver(problem, result.status, start)
        x, refined = result.x, False
        if not result.polished:
            x, refined = self._refine(problem, x)
        solution = QpSolution(
            x=x,
            y=result.y,
            status=result.status,
            iterations=result.iterations,
            polished=result.polished,
            refined=refined,
            solve_time=time.perf_counter() - start,
            osqp_time=result.run_time,
        )
        self.last = solution
        return solution

    def _second_solver(self, problem: QpProblem, status: str, start: float) -> QpSolution:
        """DAQP on the dense problem (module docstring).

        Raises:
            WbcFailed: DAQP finds no finite solution either (with OSQP's ``status``).
        """
        solution = self._dense(problem, start, status)
        self.fallbacks += 1
        return solution

    def _dense(self, problem: QpProblem, start: float, status: str | None = None) -> QpSolution:
        """The dense problem solved by the QP's dense backend (:attr:`solver`), or by DAQP
        as OSQP's second (after OSQP's ``status``).

        Raises:
            WbcFailed: It finds no finite solution (with OSQP's ``status``, if any).
        """
        name = "daqp" if status is not None else self.solver
        answer = solve_dense(name, problem)
        if not answer.found or answer.x is None:
            raise WbcFailed(status, problem, daqp_flag=answer.flag)
        duals = answer.duals if answer.duals is not None else np.zeros(len(problem.l))
        solution = QpSolution(
            x=answer.x,
            y=duals,
            status=f"solved by {name}",
            iterations=answer.iterations,
            polished=True,
            refined=False,
            solve_time=time.perf_counter() - start,
            osqp_time=0.0,
        )
        self.last = solution
        return solution

    @staticmethod
    def _accepted(result: OsqpResult) -> bool:
        """OSQP's status is accepted and its solution finite."""
        return result.status in ACCEPTED and bool(np.isfinite(result.x).all())

    def _refine(self, problem: QpProblem, x: Array) -> tuple[Array, bool]:
        """Move an unpolished ADMM solution onto its active set exactly.

        OSQP's polishing solves the QP's KKT system on the active rows; it fails on a
        degenerate active set (a site unloaded to the apex of its friction pyramid puts four
        rows on three unknowns), leaving the equalities (the dynamics) met only to the ADMM
        tolerance. Here the rows met as equalities or within the tolerance of a bound,
        :math:`A_a z = b_a`, are met exactly by the least-norm correction
        :math:`\\delta = A_a^+ (b_a - A_a z)` (an SVD least-squares solve, indifferent to
        degeneracy). Kept only if it leaves no row further outside its bounds than before.

        Returns:
            The refined solution, and whether it was kept.
        """
        eps_abs = float(self.settings.get("eps_abs", 1e-4))
        eps_rel = float(self.settings.get("eps_rel", 1e-4))
        ax = problem.A @ x
        finite_l, finite_u = np.isfinite(problem.l), np.isfinite(problem.u)
        slack = 10.0 * (eps_abs + eps_rel * np.abs(ax))
        at_lower = finite_l & (ax <= problem.l + slack)
        at_upper = finite_u & (ax >= problem.u - slack) & ~at_lower
        active = at_lower | at_upper
        bound = np.where(at_lower, problem.l, problem.u)[active]
        delta = np.linalg.lstsq(problem.A[active], bound - ax[active], rcond=None)[0]
        refined = x + delta
        before = _violation(problem, ax)
        after = _violation(problem, problem.A @ refined)
        if not np.all(np.isfinite(refined)) or after > max(before, 1e-9):
            return x, False
        return refined, True

    def _fits(self, problem: QpProblem) -> bool:
        """Whether ``problem``'s non-zeros lie in the fixed pattern, up to rounding: what
        falls outside may weigh at most ``PATTERN_TOLERANCE`` of the matrix's largest entry
        (an exact zero of the model, such as the base's :math:`M_{yz}`, comes out as
        1e-17 at some configurations)."""
        assert self._p is not None and self._a is not None
        for pattern, dense in ((self._p, problem.P), (self._a, problem.A)):
            outside = float(np.abs(dense.ravel().take(pattern.outside)).max(initial=0.0))
            if outside > 0.0 and outside > PATTERN_TOLERANCE * float(np.abs(dense).max()):
                return False
        return True

    def _setup(self, problem: QpProblem) -> OsqpWorkspace:
        self.include_pattern(problem)
        self._p = _Pattern(self._p_mask, upper=True)
        self._a = _Pattern(self._a_mask)
        solver = OsqpWorkspace(
            self._p.csc(problem.P),
            problem.q,
            self._a.csc(problem.A),
            problem.l,
            problem.u,
            self.settings,
        )
        self._solver = solver
        self.setups += 1
        return solver

    @property
    def nonzeros(self) -> tuple[int, int]:
        """Non-zeros of the fixed pattern: (upper triangle of P, A)."""
        return int(self._p_mask.sum()), int(self._a_mask.sum())
