"""The always-feasible whole-body QP (``ridempc.wbc.elastic``).

- A recorded infeasible QP (Cassie on the Hovershoes with a +30 % payload, 0.48 s into a
  fall: the closed chains' drift against the dynamics and the torque limits) has no
  solution as it is; :class:`~ridempc.wbc.qp.WholeBodyQP` still returns one, with slack on
  its soft rows, the dynamics and the torque limits met, and counts it.
- A feasible problem is solved as it is: no slack, the same solution as without the
  elastic form.
- Which constraints are soft: everything but the dynamics and the torque limits.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ridempc.solvers import solve_dense
from ridempc.wbc import constraints
from ridempc.wbc.constraints import Constraint, LinearConstraint
from ridempc.wbc.contacts import ContactSet
from ridempc.wbc.elastic import elastic_problem, solve_elastic
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.model import ModelTerms
from ridempc.wbc.qp import QpProblem, WbcFailed, WholeBodyQP
from ridempc.wbc.targets import WbcTargets

RECORDED = Path(__file__).parent / "data" / "wbc_infeasible.npz"
TOLERANCE = 1e-6  # [N, m/s^2] on the hard rows: DAQP solves its active set to ~1e-10


class _Recorded(Constraint):
    """A block of the recorded problem's rows, soft as its constraint class is."""

    def __init__(self, layout: DecisionLayout, rows: int, soft: bool) -> None:
        super().__init__(layout)
        self.rows = rows
        self.soft = soft

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        raise AssertionError("the recorded problem is solved, not built")


def _recorded() -> tuple[QpProblem, WholeBodyQP]:
    data = np.load(RECORDED)
    problem = QpProblem(data["P"], data["q"], data["A"], data["l"], data["u"])
    names = [str(n) for n in data["constraint"]]
    layout = DecisionLayout(nv=28, n_sites=4, n_motors=10, n_loops=2)  # Cassie's
    assert layout.size == problem.P.shape[0]
    blocks = []
    for name in dict.fromkeys(names):
        soft = bool(getattr(constraints, name).soft)
        blocks.append(_Recorded(layout, names.count(name), soft))
    return problem, WholeBodyQP(layout, [], blocks, solver="daqp")


def _hard_violation(problem: QpProblem, x: np.ndarray, soft: np.ndarray) -> float:
    ax = problem.A @ x
    return float(np.max(np.maximum(ax - problem.u, problem.l - ax)[~soft]))


def test_recorded_problem_is_infeasible_as_it_is() -> None:
    problem, _ = _recorded()
    assert not solve_dense("daqp", problem).found


def test_recorded_problem_gets_a_command_with_slack() -> None:
    problem, qp = _recorded()
    solution = qp.solve(problem)
    assert np.isfinite(solution.x).all()
    assert solution.slack > 1.0  # [m/s^2] the closed chains gave way
    assert solution.status == "solved with slack"
    assert qp.elastic_solves == 1
    assert _hard_violation(problem, solution.x, qp.soft) < TOLERANCE


def test_feasible_problem_takes_no_slack() -> None:
    problem, qp = _recorded()
    # the same rows, bounds moved to where a solution of the elastic problem puts them
    x, _, _ = solve_elastic(
        elastic_problem(problem.P, problem.q, problem.A, problem.l, problem.u, qp.soft)
    )
    ax = problem.A @ x
    lower = np.where(problem.l == problem.u, ax, np.minimum(problem.l, ax))
    upper = np.where(problem.l == problem.u, ax, np.maximum(problem.u, ax))
    feasible = QpProblem(problem.P, problem.q, problem.A, lower, upper)
    solution = qp.solve(feasible)
    assert solution.slack == 0.0
    assert qp.elastic_solves == 0
    direct = solve_dense("daqp", feasible)
    assert direct.x is not None
    np.testing.assert_allclose(solution.x, direct.x, atol=1e-8)


def test_only_dynamics_and_torque_limits_are_hard() -> None:
    hard = {
        name
        for name in constraints.__all__
        if isinstance(getattr(constraints, name), type)
        and issubclass(getattr(constraints, name), Constraint)
        and name not in ("Constraint",)
        and not getattr(constraints, name).soft
    }
    assert hard == {"DynamicsConstraint", "TorqueLimitConstraint", "TorqueSpeedConstraint"}


def test_backend_failure_still_raises() -> None:
    problem, qp = _recorded()
    broken = QpProblem(problem.P * np.nan, problem.q, problem.A, problem.l, problem.u)
    with pytest.raises(WbcFailed):
        qp.solve(broken)
