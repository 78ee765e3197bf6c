"""The whole-body QP made always feasible: slack on the rows that can conflict.

When the QP of a tick has no solution, its *soft* rows (those a constraint marks
:attr:`~ridempc.wbc.constraints.Constraint.soft`: closed chains, rigid springs, contact
accelerations, friction pyramids, platform tipping) are given a slack :math:`s` each, paid
for in the objective, and the *hard* rows (the floating base's dynamics and the motor
torque limits) are kept:

.. math:: \\min_{z, s}\\ \\tfrac12 z^\\top P z + q^\\top z + \\tfrac{w}{2} \\|s\\|^2
          \\quad \\text{s.t.} \\quad l_h \\le A_h z \\le u_h, \\quad
          l_s \\le A_s z + s \\le u_s.

It always has a solution: any torque within its limits, with no force, gives an
acceleration :math:`\\ddot q = M^{-1}(S^\\top \\tau + \\tau_p - h)` that meets the dynamics,
and the slack takes up every soft row. So the rider always gets a command that physics can
give, and the slack says by how much its contact model had to give way.

**An L2 penalty, not L1.** An L1 penalty is exact (no slack while the rows can hold) but
needs two signed slacks per row and positivity rows; the quadratic adds one variable per
soft row, no rows, and keeps the Hessian positive definite, which DAQP's dual active set
needs. It is exactness that the QP keeps by its order: the hard problem is solved first,
unchanged, and the elastic one only where it failed (:meth:`WholeBodyQP.solve
<ridempc.wbc.qp.WholeBodyQP.solve>`), so a ride whose QPs all solve is the same ride.

**Recorded failures.** Cassie on the Hovershoes with a payload of 30 % of her mass: from
0.45 s the estimator's passive-joint velocities reach 20-1500 rad/s in a fall, the closed
chains' drift :math:`\\dot J_{loop} v` reaches 2.5e4 m/s^2, and no torque within the limits
meets both it and the dynamics; the least slack that makes it feasible (an L1 feasibility
LP) sits on the closed-chain rows, with some on a contact-acceleration row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ridempc.solvers import DenseSolution, solve_dense

__all__ = ["SLACK_WEIGHT", "ElasticProblem", "elastic_problem", "solve_elastic"]

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]
# [-] per unit of a soft row squared: 1e4 times the WBC's largest task weight (the dog's
# force weight, 800), so a slack costs far more than any task's error of the same size;
# DAQP met the hard rows of the three recorded problems to 2e-10-3e-8 with it.
SLACK_WEIGHT: float = 1e7


@dataclass(frozen=True)
class ElasticProblem:
    """A QP with slack on its soft rows, over :math:`(z, s)`.

    Attributes:
        P: Objective Hessian, (n + k, n + k).
        q: Objective gradient, (n + k,).
        A: Constraint matrix :math:`[A\\ E]`, (m, n + k); :math:`E` places each slack on
            its row.
        l: Lower bounds, (m,).
        u: Upper bounds, (m,).
        n: Size of :math:`z`.
        rows: The soft rows that got a slack, (k,).
    """

    P: Array
    q: Array
    A: Array
    l: Array  # noqa: E741 - the QP's usual name
    u: Array
    n: int
    rows: NDArray[np.int64]


def elastic_problem(
    P: Array,  # noqa: N803 - the QP's usual names
    q: Array,
    A: Array,  # noqa: N803
    lower: Array,
    upper: Array,
    soft: Mask,
    weight: float = SLACK_WEIGHT,
) -> ElasticProblem:
    """The problem with a slack on every soft row that has a finite bound (module docstring).

    Args:
        P: Objective Hessian, (n, n).
        q: Objective gradient, (n,).
        A: Constraint matrix, (m, n).
        lower: Lower bounds, (m,).
        upper: Upper bounds, (m,).
        soft: Which rows may give way, (m,).
        weight: :math:`w`, the slack's price per unit squared [-].
    """
    n = P.shape[0]
    rows = np.flatnonzero(soft & (np.isfinite(lower) | np.isfinite(upper))).astype(np.int64)
    k = rows.size
    hessian = np.zeros((n + k, n + k))
    hessian[:n, :n] = P
    hessian[np.arange(n, n + k), np.arange(n, n + k)] = weight
    matrix = np.zeros((A.shape[0], n + k))
    matrix[:, :n] = A
    matrix[rows, n + np.arange(k)] = 1.0
    return ElasticProblem(
        hessian, np.concatenate([q, np.zeros(k)]), matrix, lower.copy(), upper.copy(), n, rows
    )


def solve_elastic(
    problem: ElasticProblem, solver: str = "daqp"
) -> tuple[Array, Array, DenseSolution]:
    """The elastic problem solved from a cold start.

    Returns:
        :math:`z`, the slack per soft row (zeros where none was needed) and the backend's
        answer (``found`` False where it found none, then :math:`z` and the slack are NaN).
    """
    answer = solve_dense(solver, problem)
    if not answer.found or answer.x is None:
        return np.full(problem.n, np.nan), np.full(problem.rows.size, np.nan), answer
    return answer.x[: problem.n], answer.x[problem.n :], answer
