"""The MPC's QP: sparse over states and inputs, built once, updated in place, solved by OSQP.

Decision vector :math:`z = (x_0, \\dots, x_N, u_0, \\dots, u_{N-1})` (not condensed: the
dynamics stay equality rows, so the KKT system is sparse and banded). Eq. (19) becomes

.. math::

    \\min_z \\tfrac12 (z - z^{ref})^\\top P (z - z^{ref}), \\quad
    P = \\mathrm{diag}(0, Q, \\dots, Q, Q_N, R, \\dots, R)

subject to :math:`l \\le A_{qp} z \\le u` with the rows, step by step:

- :math:`x_0 = \\hat x_0` (nx rows);
- :math:`x_{k+1} - A_k x_k - B_k u_k = c_k` (eq. 18, nx rows per step);
- :math:`u^{lo}_k \\le u_k \\le u^{hi}_k` (nu rows per step);
- :math:`g^{lo}_k \\le G_k u_k \\le g^{hi}_k` (the friction pyramids, m rows per step).

OSQP solves for the scaled deviation from the reference,
:math:`\\tilde z = D^{-1} (z - z^{ref})` with :math:`D` the state and input scales (forces
in units of the weight per contact), the rows of the dynamics and of the boxes are divided
by the scale of their state or input, and the polyhedral rows by their largest
coefficient: its tolerances then apply to quantities of order one whatever the units and
however far the robot has travelled (and the linear cost term is zero).

The sparsity of :math:`A_{qp}` is fixed when the QP is built: the structural non-zeros of
:math:`A_k`, :math:`B_k` and :math:`G_k` (from the pair's Jacobians and the pyramids, see
:class:`QPStructure`), stored even where a value happens to be zero. An update writes the
new values into that pattern (``Px``, ``Ax``, ``l``, ``u`` of OSQP's ``update``),
OSQP is set up once, each row held in one OSQP class (:mod:`ridempc.mpc.row_classes`, so
that new bounds never re-factor the KKT matrix), and each solve is warm-started from the
previous plan shifted by one step (primal and dual). A solve that does not end ``solved``
within the iteration budget continues for a few more iterations and its plan is used
if it converges then or if its residuals are within the bounds of
:class:`~ridempc.mpc.plan_acceptance.Acceptance`. A solve that still gives no plan (or
that OSQP finds infeasible) is solved again in its elastic form by an interior point
method (:mod:`ridempc.mpc.elastic`: the inequality rows with exact-penalty slacks, always
feasible, the QP's own solution when the QP is feasible). Only a solve beyond an optional
wall-clock time limit, or one the rescue too gives no plan, returns the previous plan
shifted by one step, flagged as a fallback, and counts as a failure.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import osqp
import scipy.sparse as sp
from numpy.typing import NDArray

from ridempc.interrupts import osqp_returned
from ridempc.mpc.elastic import ElasticRescue
from ridempc.mpc.plan import Plan, shift_plan
from ridempc.mpc.plan_acceptance import Acceptance
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.row_classes import RowClasses

__all__ = [
    "DEFAULT_SETTINGS",
    "MpcQP",
    "QPStructure",
    "SolveOutcome",
    "SolveRecord",
    "StartedSolve",
]

Array = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

# OSQP settings. The QP is scaled here (module docstring), so eps of 1e-3 is 1e-3 of each
# state's and input's tolerance, far below anything the robot feels, and OSQP's own
# equilibration, which it would redo at every matrix update (0.3 ms), is off. At 1e-4 the
# skateboard's recorded push-off-0.5 problems took p99 150 iterations and 190 at most (the
# return swings after each stroke, which start far from their push weights' tolerances),
# at 1e-3 60 and 90, and their first inputs moved by at most 0.0044 of their tolerances
# (0.1 N of force) from a solve to 1e-5. Polishing is off too: on these problems it mostly
# fails and costs a factorisation. rho = 1.0 took the fewest iterations: on the
# skateboard's push-off-0.5 and -0.7 rides the p99 fell from 234 and 220 iterations at
# rho = 0.3 to 73 and 123 (eps 1e-4; OSQP's adaptive rho starts from it and rarely gets
# there on its own), and Cassie's pairs took the same 30-40 either way. OSQP adapts rho when
# its estimate is 2 times off (``adaptive_rho_tolerance``; its default 5): on the skateboard's
# 16 s push-off-0.7 rides the slowest solves, a run of 150-170 iterations in the last
# stroke's return swing, took the QP's p99 from 6.23 to 4.34 ms (seed 2) and 4.84 to 4.10
# ms (seed 1), their first inputs within 0.032 of their tolerances; push-off-0.5's and
# Cassie's pairs' problems came out the same to the bit (their rho never moved either way).
# The budget is an iteration count, not a wall-clock time limit, so that a ride does not
# depend on the machine's load: warm-started solves take 30-40 iterations (p90) at about
# 0.05 ms each, and 400 iterations (about 20 ms) leave a third of the 33 ms period to the
# rest of the controller. A ``time_limit`` [s] may still be given (a deadline, as on
# hardware); a solve beyond it then falls back too.
DEFAULT_SETTINGS: dict[str, Any] = {
    "verbose": False,
    "eps_abs": 1e-3,
    "eps_rel": 1e-3,
    "max_iter": 400,
    "rho": 1.0,
    "scaling": 0,
    "check_termination": 10,
    "adaptive_rho_tolerance": 2.0,
    "polishing": False,
    "warm_starting": True,
}
_SOLVED = osqp.SolverStatus.OSQP_SOLVED
# the statuses of a solve that ended its budget unconverged (continued, see Acceptance)
_UNCONVERGED = (osqp.SolverStatus.OSQP_MAX_ITER_REACHED, osqp.SolverStatus.OSQP_SOLVED_INACCURATE)
# the statuses of a solve that gave no plan and is solved again in its elastic form
_RESCUED = (
    *_UNCONVERGED,
    osqp.SolverStatus.OSQP_PRIMAL_INFEASIBLE,
    osqp.SolverStatus.OSQP_PRIMAL_INFEASIBLE_INACCURATE,
)
# OSQP's infinity, to which its Python ``update`` clips the bounds (written here as it does)
_INFINITY = float(osqp.constant("OSQP_INFTY"))
_PATTERN_TOLERANCE = 1e-9  # values this small outside the pattern are round-off


@dataclass(frozen=True)
class QPStructure:
    """Which entries of the per-step matrices may be non-zero (fixed when the QP is built).

    Attributes:
        state_pattern: Of :math:`A_k` (nx x nx).
        input_pattern: Of :math:`B_k` (nx x nu).
        constraint_pattern: Of :math:`G_k` (m x nu).
    """

    state_pattern: BoolArray
    input_pattern: BoolArray
    constraint_pattern: BoolArray

    @classmethod
    def of(cls, problem: MpcProblem) -> QPStructure:
        """The non-zeros of one problem (any step), with the diagonal of :math:`A_k`."""
        state = np.any(problem.A != 0.0, axis=0) | np.eye(problem.nx, dtype=bool)
        return cls(
            state,
            np.any(problem.B != 0.0, axis=0),
            np.any(problem.constraint_matrix != 0.0, axis=0),
        )


class SolveRecord(NamedTuple):
    """One solve: OSQP's status, wall time [s], iterations, and whether it fell back."""

    status: str
    solve_time: float
    iterations: int
    fallback: bool


class StartedSolve(NamedTuple):
    """A QP updated and warm-started (:meth:`MpcQP.start`): its problem, the reference
    :math:`z^{ref}` it is solved about, and the time that took [s]."""

    problem: MpcProblem
    reference: Array
    seconds: float


class SolveOutcome(NamedTuple):
    """OSQP's run (:meth:`MpcQP.run`): its result (None on a solver error), status,
    iterations, whether it solved, and its time [s]."""

    result: Any
    status: str
    iterations: int
    ok: bool
    seconds: float


class _Result(NamedTuple):
    """One OSQP solve (:meth:`MpcQP.run`): the primal and dual solutions and its info
    (``status``, ``status_val``, ``iter``)."""

    x: Array
    y: Array
    info: Any


class _Update(NamedTuple):
    """What one solve writes into OSQP: the diagonal of :math:`D P D`, the values of
    :math:`A_{qp} D` on the pattern, the scaled bounds, and the warm start (primal and
    dual; None: none)."""

    weights: Array
    values: Array
    lower: Array
    upper: Array
    primal: Array | None
    dual: Array | None


class MpcQP:
    """The sparse MPC QP, built once for a horizon, sizes and :class:`QPStructure`.

    Attributes:
        horizon: N.
        nx: State size.
        nu: Input size.
        n_constraints: Polyhedral rows per step, m.
        structure: The fixed sparsity.
        history: One :class:`SolveRecord` per :meth:`solve`.
        failures: Solves that fell back.
        row_classes: The rows' OSQP classes as held (None: as the bounds give them).
    """

    def __init__(
        self,
        problem: MpcProblem,
        structure: QPStructure | None = None,
        state_scale: Array | None = None,
        input_scale: Array | None = None,
        **settings: Any,
    ) -> None:
        """Build the QP's pattern from ``problem`` (and ``structure``) and set up OSQP.

        Args:
            problem: A first problem: its sizes and values initialise the QP.
            structure: The sparsity every later problem stays within (default: the
                non-zeros of ``problem``).
            state_scale: Typical size of each state's deviation (nx, default ones).
            input_scale: Typical size of each input's deviation (nu, default ones), e.g.
                the weight per contact [N] for the forces.
            settings: OSQP settings over :data:`DEFAULT_SETTINGS`, ``row_classes``:
                True (default) holds each row in one OSQP class
                (:mod:`~ridempc.mpc.row_classes`: new bounds never re-factor the KKT
                matrix), False gives each row the class its bounds ask for, and
                ``acceptance``: the rule for an unconverged solve
                (:class:`~ridempc.mpc.plan_acceptance.Acceptance`, default its own; None:
                no unconverged solve accepted), and ``rescue``: the elastic solve of a QP
                that gives no plan (:class:`~ridempc.mpc.elastic.ElasticRescue`, default
                its own; None: none, the solve fails).
        """
        self.horizon, self.nx, self.nu = problem.horizon, problem.nx, problem.nu
        self.n_constraints = problem.n_constraints
        self.structure = structure or QPStructure.of(problem)
        self._check_structure()
        held = bool(settings.pop("row_classes", True))
        acceptance = settings.pop("acceptance", Acceptance())
        self.acceptance: Acceptance = Acceptance(0) if acceptance is None else acceptance
        self.rescue: ElasticRescue | None = settings.pop("rescue", ElasticRescue())
        self.settings = {**DEFAULT_SETTINGS, **settings}
        limit = self.settings.get("time_limit")
        self.time_limit: float | None = None if limit is None else float(limit)
        self.history: list[SolveRecord] = []
        self.failures = 0
        self._previous: Plan | None = None
        self._previous_dual: Array | None = None
        self._staged: _Update | None = None  # started, not yet written into OSQP
        n = self.horizon
        sx = np.ones(self.nx) if state_scale is None else np.asarray(state_scale, dtype=float)
        su = np.ones(self.nu) if input_scale is None else np.asarray(input_scale, dtype=float)
        if sx.shape != (self.nx,) or su.shape != (self.nu,) or min(sx.min(), su.min()) <= 0:
            raise ValueError("MpcQP: scales must be positive, one per state and per input")
        self._scale = np.concatenate([np.tile(sx, n + 1), np.tile(su, n)])
        # Rows in scaled units: states' rows by their scale, boxes by the inputs'.
        self._row_scale = 1.0 / np.concatenate(
            [np.tile(sx, n + 1), np.tile(su, n), np.ones(n * self.n_constraints)]
        )
        self._input_scale = su
        first = (n + 1) * self.nx  # u_0 in z
        self._first_input = slice(first, first + self.nu)
        s = self.structure
        self._outside_at = {
            name: np.flatnonzero(~pattern)
            for name, pattern in (
                ("A", s.state_pattern),
                ("B", s.input_pattern),
                ("constraint_matrix", s.constraint_pattern),
            )
        }
        self._build_pattern()
        hessian, csc, lower, upper = self.whole(problem)
        self._solver = osqp.OSQP()
        self._solver.setup(hessian, np.zeros(self.n_variables), csc, lower, upper, **self.settings)
        self.row_classes = RowClasses(lower, upper, self._indices) if held else None

    @property
    def n_variables(self) -> int:
        return (self.horizon + 1) * self.nx + self.horizon * self.nu

    @property
    def n_rows(self) -> int:
        n = self.horizon
        return self.nx + n * (self.nx + self.nu + self.n_constraints)

    @property
    def nnz(self) -> int:
        """Stored entries of :math:`A_{qp}` (fixed)."""
        return len(self._indices)

    @property
    def pattern(self) -> tuple[IntArray, IntArray]:
        """CSC ``indices`` and ``indptr`` of :math:`A_{qp}` (fixed)."""
        return self._indices.copy(), self._indptr.copy()

    def _check_structure(self) -> None:
        s, nx, nu = self.structure, self.nx, self.nu
        for name, got, expected in (
            ("state_pattern", s.state_pattern.shape, (nx, nx)),
            ("input_pattern", s.input_pattern.shape, (nx, nu)),
            ("constraint_pattern", s.constraint_pattern.shape, (self.n_constraints, nu)),
        ):
            if got != expected:
                raise ValueError(f"MpcQP: {name} has shape {got}, expected {expected}")

    def _build_pattern(self) -> None:
        """COO triplets of :math:`A_{qp}`, each pointing into the value vector of
        :meth:`_data`, sorted once into CSC order."""
        n, nx, nu, m = self.horizon, self.nx, self.nu, self.n_constraints
        s = self.structure
        x_at = np.arange(n + 1) * nx
        u_at = (n + 1) * nx + np.arange(n) * nu
        rows: list[IntArray] = []
        cols: list[IntArray] = []
        eye_x, eye_u = np.arange(nx), np.arange(nu)
        # Identities (value 1): x_0, x_{k+1} in the dynamics, u_k in the boxes.
        rows.append(eye_x)
        cols.append(eye_x)
        for k in range(n):
            rows.append(nx + k * nx + eye_x)
            cols.append(x_at[k + 1] + eye_x)
        box_at = nx + n * nx
        for k in range(n):
            rows.append(box_at + k * nu + eye_u)
            cols.append(u_at[k] + eye_u)
        n_ones = sum(len(r) for r in rows)
        self._a_rows, self._a_cols = np.nonzero(s.state_pattern)
        self._b_rows, self._b_cols = np.nonzero(s.input_pattern)
        self._g_rows, self._g_cols = np.nonzero(s.constraint_pattern)
        # each pattern's entries as flat indices of its matrix (one take per stack)
        self._a_at = np.flatnonzero(s.state_pattern)
        self._b_at = np.flatnonzero(s.input_pattern)
        self._g_at = np.flatnonzero(s.constraint_pattern)
        for k in range(n):
            rows.append(nx + k * nx + self._a_rows)
            cols.append(x_at[k] + self._a_cols)
        for k in range(n):
            rows.append(nx + k * nx + self._b_rows)
            cols.append(u_at[k] + self._b_cols)
        poly_at = box_at + n * nu
        for k in range(n):
            rows.append(poly_at + k * m + self._g_rows)
            cols.append(u_at[k] + self._g_cols)
        all_rows, all_cols = np.concatenate(rows), np.concatenate(cols)
        order = np.lexsort((all_rows, all_cols))
        self._source = order  # value-vector index of each CSC entry
        self._indices = all_rows[order].astype(np.int64)
        self._columns = all_cols[order]
        self._column_scale = self._scale[self._columns]  # D at each stored entry
        counts = np.bincount(all_cols, minlength=self.n_variables)
        self._indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        self._ones = np.ones(n_ones)
        # Shift by one step, for warm starts: new index -> old index.
        steps = np.minimum(np.arange(n + 1) + 1, n)
        x_shift = (steps[:, None] * nx + eye_x).ravel()
        u_shift = ((n + 1) * nx + np.minimum(np.arange(n) + 1, n - 1)[:, None] * nu + eye_u).ravel()
        self._primal_shift = np.concatenate([x_shift, u_shift])
        block = np.minimum(np.arange(n) + 1, n - 1)
        self._dual_shift = np.concatenate(
            [
                eye_x,
                (nx + block[:, None] * nx + eye_x).ravel(),
                (box_at + block[:, None] * nu + eye_u).ravel(),
                (poly_at + block[:, None] * m + np.arange(m)).ravel(),
            ]
        )

    def _outside(self, name: str, values: Array, pattern: BoolArray) -> None:
        outside = self._outside_at[name]  # flat indices of the entries off the pattern
        if not outside.size:
            return
        largest = float(np.abs(values.reshape(len(values), -1).take(outside, axis=1)).max())
        if largest <= _PATTERN_TOLERANCE:  # below the bound whatever the matrix's scale
            return
        stray = np.abs(values[:, ~pattern])
        if stray.max() > _PATTERN_TOLERANCE * max(1.0, np.abs(values).max()):
            raise ValueError(
                f"MpcQP: {name} has a non-zero outside the QP's fixed pattern "
                f"(largest {stray.max():.3g}); build the QP with a QPStructure covering it"
            )

    def _data(self, problem: MpcProblem) -> tuple[Array, Array, Array]:
        """Values of :math:`A_{qp} D` (rows scaled) in CSC order, and the bounds of
        :math:`\\tilde z` (see the module docstring)."""
        s = self.structure
        self._outside("A", problem.A, s.state_pattern)
        self._outside("B", problem.B, s.input_pattern)
        self._outside("constraint_matrix", problem.constraint_matrix, s.constraint_pattern)
        g = problem.constraint_matrix
        largest = np.abs(g * self._input_scale).max(axis=2)  # N x m
        row_scale = self._row_scale.copy()
        row_scale[self.n_rows - g.shape[0] * g.shape[1] :] = (
            1.0 / np.where(largest > 0.0, largest, 1.0).ravel()
        )
        values = np.concatenate(
            [
                self._ones,
                -problem.A.reshape(len(g), -1).take(self._a_at, axis=1).ravel(),
                -problem.B.reshape(len(g), -1).take(self._b_at, axis=1).ravel(),
                g.reshape(len(g), -1).take(self._g_at, axis=1).ravel(),
            ]
        )[self._source]
        values *= self._column_scale * row_scale[self._indices]
        x_ref, u_ref = problem.state_reference, problem.input_reference
        at_reference = np.concatenate(
            [
                x_ref[0],
                (
                    x_ref[1:]
                    - np.einsum("kij,kj->ki", problem.A, x_ref[:-1])
                    - np.einsum("kij,kj->ki", problem.B, u_ref)
                ).ravel(),
                u_ref.ravel(),
                np.einsum("kij,kj->ki", g, u_ref).ravel(),
            ]
        )
        x0, c = problem.initial_state, problem.c.ravel()
        lower = np.concatenate(
            [x0, c, problem.input_lower.ravel(), problem.constraint_lower.ravel()]
        )
        upper = np.concatenate(
            [x0, c, problem.input_upper.ravel(), problem.constraint_upper.ravel()]
        )
        return values, (lower - at_reference) * row_scale, (upper - at_reference) * row_scale

    def _weights(self, problem: MpcProblem) -> Array:
        """Diagonal of :math:`D P D`."""
        n = self.horizon
        weights = np.concatenate(
            [
                np.zeros(self.nx),  # x_0 is fixed by its rows
                np.tile(problem.state_weights, n - 1),
                problem.final_weights,
                np.broadcast_to(problem.input_weights, (n, self.nu)).ravel(),
            ]
        )
        return weights * self._scale**2

    @staticmethod
    def _reference(problem: MpcProblem) -> Array:
        return np.concatenate([problem.state_reference.ravel(), problem.input_reference.ravel()])

    def _check_sizes(self, problem: MpcProblem) -> None:
        sizes = (problem.horizon, problem.nx, problem.nu, problem.n_constraints)
        if sizes != (self.horizon, self.nx, self.nu, self.n_constraints):
            raise ValueError(
                f"MpcQP: problem of sizes (N, nx, nu, m) = {sizes}, the QP was built for "
                f"{(self.horizon, self.nx, self.nu, self.n_constraints)}"
            )

    def matrices(self, problem: MpcProblem) -> tuple[sp.csc_matrix, sp.csc_matrix]:
        """The scaled :math:`P` and :math:`A_{qp}` that ``problem`` writes into the QP, on the
        fixed pattern (for tests and inspection; :meth:`update` passes only their values).

        Raises:
            ValueError: As :meth:`update`.
        """
        hessian, constraints, _, _ = self.whole(problem)
        return hessian, constraints

    def bounds(self, problem: MpcProblem) -> tuple[Array, Array]:
        """The scaled :math:`l, u` that ``problem`` writes into the QP, with :meth:`matrices`
        the whole QP :math:`\\min \\tfrac12 z^\\top P z`, :math:`l \\le A_{qp} z \\le u`.

        Raises:
            ValueError: As :meth:`update`.
        """
        self._check_sizes(problem)
        _, lower, upper = self._data(problem)
        return lower, upper

    def whole(self, problem: MpcProblem) -> tuple[sp.csc_matrix, sp.csc_matrix, Array, Array]:
        """:meth:`matrices` and :meth:`bounds` at once, ``problem`` read once: the scaled
        :math:`P, A_{qp}, l, u` (a solver set up from scratch, the elastic rescue, the bench).

        Raises:
            ValueError: As :meth:`update`.
        """
        self._check_sizes(problem)
        values, lower, upper = self._data(problem)
        n = self.n_variables
        hessian = sp.csc_matrix((self._weights(problem), np.arange(n), np.arange(n + 1)), (n, n))
        constraints = sp.csc_matrix(
            (values, self._indices.copy(), self._indptr.copy()), shape=(self.n_rows, n)
        )
        return hessian, constraints, lower, upper

    def update(self, problem: MpcProblem) -> None:
        """Write ``problem``'s values into the fixed pattern (no new setup).

        Raises:
            ValueError: Sizes differ from the QP's, or a matrix has a non-zero outside
                the QP's :class:`QPStructure` (a wrong pair, not a solver failure).
        """
        self._write(self._values(problem))

    def _values(self, problem: MpcProblem) -> _Update:
        """What :meth:`update` writes into OSQP for ``problem`` (no warm start).

        Raises:
            ValueError: As :meth:`update`.
        """
        self._check_sizes(problem)
        values, lower, upper = self._data(problem)
        if self.row_classes is not None:
            values, lower, upper = self.row_classes.hold(values, lower, upper)
        return _Update(self._weights(problem), values, lower, upper, None, None)

    def _write(self, update: _Update) -> None:
        """``update`` written into OSQP: the values, then the warm start if any; into the
        extension's solver, as OSQP's Python ``update`` writes them (the bounds clipped to
        its infinity, then the vectors, then the matrices), without what it adds per call
        (importing the extension twice to read that infinity, copies kept for derivatives
        nobody asks for)."""
        solver = self._solver._solver
        lower = np.maximum(update.lower, -_INFINITY)
        solver.update_data_vec(q=None, l=lower, u=np.minimum(update.upper, _INFINITY))
        solver.update_data_mat(P_x=update.weights, P_i=None, A_x=update.values, A_i=None)
        if update.primal is not None:
            solver.warm_start(update.primal, update.dual)

    def _unpack(self, z: Array) -> tuple[Array, Array]:
        n, nx = self.horizon, self.nx
        states = z[: (n + 1) * nx].reshape(n + 1, nx)
        inputs = z[(n + 1) * nx :].reshape(n, self.nu)
        return states, inputs

    def solve(self, problem: MpcProblem) -> Plan:
        """Update the QP with ``problem``, warm-start it, solve it (see the module docstring).

        Never raises for a failed solve: an infeasible problem, a solver error or a solve
        beyond the iteration budget or time limit returns the previous plan shifted by one
        step (or, before any plan, the problem's reference) with ``fallback`` set.

        Raises:
            ValueError: As :meth:`update`.
        """
        started = self.start(problem)
        return self.finish(started, self.run())

    def start(self, problem: MpcProblem) -> StartedSolve:
        """The first part of :meth:`solve`: the values of ``problem`` and the warm start
        made ready for OSQP. :meth:`run` then writes them in and solves (OSQP releases
        Python's lock while it refactors its KKT matrix and iterates, so that may go on in
        another thread) and :meth:`finish` turns the outcome into the plan.

        Raises:
            ValueError: As :meth:`update`.
        """
        begin = time.perf_counter()
        update = self._values(problem)
        reference = self._reference(problem)
        if self._previous is not None:
            states, inputs = self._previous.states, self._previous.inputs
            z = np.concatenate([states.ravel(), inputs.ravel()])[self._primal_shift]
            y = None if self._previous_dual is None else self._previous_dual[self._dual_shift]
            update = update._replace(primal=(z - reference) / self._scale, dual=y)
        self._staged = update
        return StartedSolve(problem, reference, time.perf_counter() - begin)

    def run(self) -> SolveOutcome:
        """The started QP (:meth:`start`) written into OSQP (its KKT matrix refactored)
        and solved.

        Raises:
            Interrupted: In the main thread, when the command was interrupted
                (:func:`~ridempc.interrupts.osqp_returned`); nothing else.
        """
        begin = time.perf_counter()
        staged, self._staged = self._staged, None
        try:
            if staged is not None:
                self._write(staged)
            result = self._run_osqp()
            status, iterations = str(result.info.status), int(result.info.iter)
            ok = result.info.status_val == _SOLVED
            if not ok and self.acceptance.enabled and result.info.status_val in _UNCONVERGED:
                result, status, iterations, ok = self._continue(result, iterations)
        except (osqp.OSQPException, ValueError) as exc:
            result, status, iterations, ok = None, f"solver error ({exc!r})", 0, False
        osqp_returned(result.info.status_val if result is not None else _SOLVED)
        return SolveOutcome(result, status, iterations, ok, time.perf_counter() - begin)

    def _continue(self, result: _Result, iterations: int) -> tuple[_Result, str, int, bool]:
        """An unconverged solve continued from its last iterates for the acceptance's
        extra iterations (:mod:`~ridempc.mpc.plan_acceptance`): its result, status, total
        iterations and whether its plan is used (converged, or within the bounds)."""
        osqp_returned(result.info.status_val)  # an interrupt ends it here
        before = np.array(result.x[self._first_input], dtype=float)
        self._solver.update_settings(max_iter=self.acceptance.extra_iterations)
        try:
            result = self._run_osqp()  # warm_starting: from the last x, z, y and rho
        finally:
            self._solver.update_settings(max_iter=int(self.settings["max_iter"]))
        iterations += int(result.info.iter)
        status = str(result.info.status)
        if result.info.status_val == _SOLVED:
            return result, status, iterations, True
        accepted = result.info.status_val in _UNCONVERGED and self.acceptance.accepts(
            float(result.info.prim_res), before, result.x[self._first_input]
        )
        return result, Acceptance.status(status) if accepted else status, iterations, accepted

    def _rescues(self, outcome: SolveOutcome) -> bool:
        """Whether a solve that gave no plan is solved again in its elastic form: one
        OSQP ended unconverged or found infeasible (not a deadline, an interrupt or a
        solver error)."""
        result = outcome.result
        return self.rescue is not None and result is not None and result.info.status_val in _RESCUED

    def _run_osqp(self) -> _Result:
        """OSQP's solve on the extension's solver: its solution and info as OSQP's Python
        ``solve`` returns them, without the copy of every info field it makes per call."""
        solver = self._solver._solver
        solver.solve()
        solution = solver.solution
        return _Result(solution.x, solution.y, solver.info)

    def finish(self, started: StartedSolve, outcome: SolveOutcome) -> Plan:
        """The plan of a started (:meth:`start`) and run (:meth:`run`) solve, or the
        fallback (:meth:`solve`). Its ``solve_time`` is the time spent in :meth:`start`,
        :meth:`run` and here, not the wall time between them."""
        begin = time.perf_counter()
        status, iterations, ok = outcome.status, outcome.iterations, outcome.ok
        elapsed = started.seconds + outcome.seconds
        if ok and self.time_limit is not None and elapsed > self.time_limit:
            status, ok = f"time limit exceeded ({elapsed * 1e3:.1f} ms)", False
        problem, result = started.problem, outcome.result
        scaled = np.asarray(result.x, dtype=float) if ok else None
        if ok:
            self._previous_dual = np.asarray(result.y, dtype=float).copy()
        elif self._rescues(outcome):
            assert self.rescue is not None
            rescued = self.rescue.solve(*self.whole(problem))
            if rescued.z is not None:  # the previous dual kept for the next warm start
                scaled, status = rescued.z, f"{status}, elastic (slack {rescued.slack:.2g})"
        if scaled is not None:
            z = started.reference + self._scale * scaled
            states, inputs = self._unpack(z)
            elapsed += time.perf_counter() - begin
            plan = Plan(states, inputs, inputs[0].copy(), status, elapsed, False, iterations)
        else:
            self.failures += 1
            elapsed += time.perf_counter() - begin
            if self._previous is not None:
                plan = shift_plan(self._previous, status, elapsed, iterations)
            else:
                u_ref = problem.input_reference
                x_ref = problem.state_reference
                plan = Plan(
                    x_ref.copy(), u_ref.copy(), u_ref[0].copy(), status, elapsed, True, iterations
                )
        self._previous = plan
        self.history.append(SolveRecord(status, elapsed, iterations, plan.fallback))
        return plan
