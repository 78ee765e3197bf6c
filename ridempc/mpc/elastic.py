"""The MPC's QP always solvable: its inequality rows made elastic and solved by an interior
point method (:class:`ElasticRescue`), when OSQP gives no plan.

The MPC's QP (:mod:`ridempc.mpc.qp`), :math:`\\min \\tfrac12 z^\\top P z` subject to
:math:`l \\le A z \\le u`, holds equality rows (the initial state, the dynamics, inputs
pinned to a value) and inequality rows (the input boxes, the friction pyramids and load
limits). Only the inequality rows can conflict with one another; the equality rows always
have a solution (each step's state follows from its inputs). The elastic QP gives each
inequality row :math:`i` a slack :math:`s_i \\ge 0` with an exact (L1) penalty:

.. math::

    \\min_{z, s} \\tfrac12 z^\\top P z + w \\mathbf 1^\\top s \\quad \\text{s.t.} \\quad
    A_{eq} z = b, \\quad l_i - s_i \\le a_i^\\top z \\le u_i + s_i, \\quad s \\ge 0

It is always feasible, and when the QP is feasible and :math:`w` exceeds the largest of
its optimal multipliers, its solution is the QP's own with :math:`s = 0` (the exact
penalty theorem); when the QP is infeasible it is the plan that violates the rows least
(in the L1 sense, each row in its own scaled units) and is otherwise optimal.

It is solved by the registry's rescue solver (:attr:`~ridempc.solvers.QpKind.rescue`,
PIQP, an interior point method: 13-15 iterations on the recorded problems where OSQP
ran out of iterations, whose ADMM converges slowly with many active rows), from a cold
start: 20-60 ms a solve on the recorded problems of Cassie's boards (a loaded machine),
spent only on the solves that give no plan otherwise; its first inputs there matched
Clarabel's optimum to 1e-5 tolerances with slacks below 1e-10.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ridempc.solvers import QP_KINDS

__all__ = ["PENALTY", "ElasticRescue", "ElasticSolution", "elastic_problem"]

Array = NDArray[np.float64]

# [cost per tolerance of violation] The exact penalty's weight, in the QP's scaled units
# (each row in tolerances, the cost of one tolerance of deviation about one): the
# multipliers of the recorded problems where OSQP failed reached 4e4 (a rider 10-28
# tolerances off her reference), so 1e6 leaves a factor of 25 before a feasible QP's plan
# would trade a violation for cost.
PENALTY: float = 1e6
# [-] Bounds beyond this are no bound (OSQP's infinity is 1e30; the QP's are of order one)
_FREE: float = 1e20


class ElasticSolution(NamedTuple):
    """The elastic QP's answer.

    Attributes:
        z: The QP's variables (scaled), or None when the solver found none.
        slack: The largest row violation :math:`\\max_i s_i` [tolerances] (0 for a
            feasible QP).
        seconds: The solve's wall time [s].
    """

    z: Array | None
    slack: float
    seconds: float


def elastic_problem(
    hessian: sp.spmatrix, constraints: sp.spmatrix, lower: Array, upper: Array, penalty: float
) -> tuple[dict[str, Any], int]:
    """The elastic QP (module docstring) in qpsolvers' form
    (:math:`\\min \\tfrac12 v^\\top P v + q^\\top v`, :math:`G v \\le h`, :math:`A v = b`,
    :math:`lb \\le v \\le ub`) over :math:`v = (z, s)`.

    Args:
        hessian: :math:`P` (n x n).
        constraints: :math:`A` (rows x n).
        lower: :math:`l` (rows; -inf: none).
        upper: :math:`u` (rows; inf: none).
        penalty: :math:`w`.

    Returns:
        The problem's arrays by qpsolvers' names, and the number of slacks.
    """
    a = sp.csr_matrix(constraints)
    n = a.shape[1]
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    has_lower, has_upper = lower > -_FREE, upper < _FREE
    equal = has_lower & has_upper & (lower == upper)
    soft = np.flatnonzero(~equal & (has_lower | has_upper))
    m = len(soft)
    slack_of = np.full(len(lower), -1)
    slack_of[soft] = np.arange(m)
    up, low = soft[has_upper[soft]], soft[has_lower[soft]]
    slacks_up = sp.csr_matrix((-np.ones(len(up)), (np.arange(len(up)), slack_of[up])), (len(up), m))
    slacks_low = sp.csr_matrix(
        (-np.ones(len(low)), (np.arange(len(low)), slack_of[low])), (len(low), m)
    )
    g = sp.vstack([sp.hstack([a[up], slacks_up]), sp.hstack([-a[low], slacks_low])]).tocsc()
    h = np.concatenate([upper[up], -lower[low]])
    eq = np.flatnonzero(equal)
    problem: dict[str, Any] = {
        "P": sp.block_diag([sp.csc_matrix(hessian), sp.csc_matrix((m, m))]).tocsc(),
        "q": np.concatenate([np.zeros(n), np.full(m, penalty)]),
        "G": g,
        "h": h,
        "A": sp.hstack([a[eq], sp.csr_matrix((len(eq), m))]).tocsc(),
        "b": lower[eq],
        "lb": np.concatenate([np.full(n, -np.inf), np.zeros(m)]),
        "ub": np.full(n + m, np.inf),
    }
    return problem, m


@dataclass(frozen=True)
class ElasticRescue:
    """Solves a QP's elastic form (module docstring) with the rescue solver.

    Attributes:
        solver: The qpsolvers backend (default the registry's rescue solver).
        penalty: :math:`w` [cost per tolerance of violation].
    """

    solver: str = QP_KINDS["mpc"].rescue or "piqp"
    penalty: float = PENALTY

    def solve(
        self, hessian: sp.spmatrix, constraints: sp.spmatrix, lower: Array, upper: Array
    ) -> ElasticSolution:
        """The elastic QP of :math:`\\min \\tfrac12 z^\\top P z`, :math:`l \\le A z \\le u`
        solved from a cold start (its :math:`z`, None if the solver failed)."""
        import qpsolvers

        arrays, m = elastic_problem(hessian, constraints, lower, upper, self.penalty)
        n = constraints.shape[1]
        started = time.perf_counter()
        try:
            solution = qpsolvers.solve_problem(qpsolvers.Problem(**arrays), solver=self.solver)
        except (ValueError, qpsolvers.QPError):
            solution = None
        seconds = time.perf_counter() - started
        if solution is None or not solution.found or solution.x is None:
            return ElasticSolution(None, float("nan"), seconds)
        v = np.asarray(solution.x, dtype=float)
        if not np.all(np.isfinite(v)):
            return ElasticSolution(None, float("nan"), seconds)
        slack = float(np.max(v[n:], initial=0.0)) if m else 0.0
        return ElasticSolution(v[:n].copy(), max(slack, 0.0), seconds)
