"""A plan OSQP did not fully converge: continued, then used only within its residual bounds;
a QP that still gives no plan, or is infeasible, solved in its elastic form."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import osqp_tight

from ridempc.mpc.elastic import ElasticRescue, elastic_problem
from ridempc.mpc.plan_acceptance import Acceptance
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.qp import MpcQP

DT = 0.1  # [s]
HORIZON = 8


def _pushed_cart(x0: float = 3.0) -> MpcProblem:
    """A cart (position, velocity) 3 m from its reference, pushed by two forces whose sum
    is bounded by a pyramid-like row on every step (active over most of the horizon)."""
    a = np.array([[1.0, DT], [0.0, 1.0]])
    b = np.array([[0.5 * DT**2, 0.5 * DT**2], [DT, DT]])
    n = HORIZON
    return MpcProblem(
        initial_state=np.array([x0, 0.0]),
        A=np.tile(a, (n, 1, 1)),
        B=np.tile(b, (n, 1, 1)),
        c=np.zeros((n, 2)),
        state_reference=np.zeros((n + 1, 2)),
        input_reference=np.zeros((n, 2)),
        state_weights=np.array([100.0, 1.0]),
        input_weights=np.array([0.01, 0.01]),
        input_lower=np.full((n, 2), -5.0),
        input_upper=np.full((n, 2), 5.0),
        constraint_matrix=np.tile(np.array([[1.0, 1.0], [1.0, -1.0]]), (n, 1, 1)),
        constraint_lower=np.tile([-3.0, -0.5], (n, 1)),
        constraint_upper=np.tile([3.0, 0.5], (n, 1)),
        dt=DT,
    )


def _optimum_first_input(qp: MpcQP, problem: MpcProblem) -> np.ndarray:
    p, a = qp.matrices(problem)
    lower, upper = qp.bounds(problem)
    z = osqp_tight(p.toarray(), np.zeros(p.shape[0]), a.toarray(), lower, upper)
    first = (qp.horizon + 1) * qp.nx
    return problem.input_reference[0] + qp._scale[first : first + qp.nu] * z[first : first + qp.nu]


def test_the_rule_accepts_only_within_both_bounds() -> None:
    rule = Acceptance(extra_iterations=50, residual=0.2, change=0.1)
    before = np.array([1.0, -1.0])
    assert rule.accepts(0.19, before, before + 0.09)
    assert not rule.accepts(0.21, before, before)  # rows violated beyond the bound
    assert not rule.accepts(0.1, before, before + np.array([0.0, 0.11]))  # u_0 still moving
    assert not rule.accepts(float("nan"), before, before)
    assert not rule.accepts(0.1, before, np.array([np.nan, 1.0]))
    assert not Acceptance(extra_iterations=0).accepts(0.0, before, before)  # disabled
    assert Acceptance.status("maximum iterations reached") == "maximum iterations reached, accepted"


@pytest.mark.parametrize("field", ["extra_iterations", "residual", "change"])
def test_the_rule_refuses_negative_bounds(field: str) -> None:
    with pytest.raises(ValueError, match=field):
        Acceptance(**{field: -1})


def test_an_unconverged_solve_within_its_bounds_gives_a_plan() -> None:
    problem = _pushed_cart()
    rule = Acceptance(extra_iterations=200, residual=0.2, change=0.1)
    qp = MpcQP(problem, max_iter=10, acceptance=rule)  # a budget far too small
    plan = qp.solve(problem)
    assert not plan.fallback and qp.failures == 0
    assert plan.status == "solved" or plan.status.endswith(", accepted")
    assert plan.iterations > 10  # continued past its budget
    tolerance = 1.0 / np.sqrt(problem.input_weights)
    error = np.abs(plan.first_input - _optimum_first_input(qp, problem)) / tolerance
    assert error.max() < 2 * rule.change + rule.residual


def test_an_unconverged_solve_beyond_its_bounds_falls_back() -> None:
    problem = _pushed_cart()
    strict = Acceptance(extra_iterations=5, residual=0.0, change=0.0)
    plan = MpcQP(problem, max_iter=10, acceptance=strict, rescue=None).solve(problem)
    assert plan.fallback and plan.status == "maximum iterations reached"
    off = MpcQP(problem, max_iter=10, acceptance=None, rescue=None).solve(problem)
    assert off.fallback and off.iterations == 10


def test_a_converged_solve_is_untouched_by_the_rule() -> None:
    problem = _pushed_cart(0.1)
    plans = [MpcQP(problem, acceptance=rule).solve(problem) for rule in (Acceptance(), None)]
    assert plans[0].status == plans[1].status == "solved"
    assert plans[0].iterations == plans[1].iterations
    np.testing.assert_array_equal(plans[0].inputs, plans[1].inputs)


def test_an_infeasible_qp_gets_a_plan_with_slack() -> None:
    problem = _pushed_cart()
    lower = problem.constraint_lower.copy()
    lower[:, 0] = 12.0  # the forces' sum above 12 N, each force's box at most 5 N
    infeasible = replace(problem, constraint_lower=lower, constraint_upper=lower + 1.0)
    qp = MpcQP(infeasible)
    plan = qp.solve(infeasible)
    assert not plan.fallback and "elastic" in plan.status and qp.failures == 0
    # the least violation: the boxes held (to the interior point's accuracy), the sum gave
    assert np.all(np.abs(plan.inputs) <= 5.0 + 1e-3)
    assert plan.inputs.sum(axis=1) == pytest.approx(np.full(HORIZON, 10.0), abs=1e-3)
    off = MpcQP(infeasible, rescue=None).solve(infeasible)
    assert off.fallback and "infeasible" in off.status


def test_a_feasible_rescue_is_the_qps_own_optimum() -> None:
    problem = _pushed_cart()
    qp = MpcQP(problem, max_iter=10, acceptance=None)  # no plan from OSQP itself
    plan = qp.solve(problem)
    assert not plan.fallback and plan.status.startswith("maximum iterations reached, elastic")
    tolerance = 1.0 / np.sqrt(problem.input_weights)
    error = np.abs(plan.first_input - _optimum_first_input(qp, problem)) / tolerance
    assert error.max() < 1e-4  # the exact penalty: no slack where the QP is feasible


def test_the_elastic_form_softens_only_the_inequality_rows() -> None:
    hessian = sp.identity(2, format="csc")
    rows = sp.csc_matrix(np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]))
    arrays, slacks = elastic_problem(
        hessian, rows, np.array([1.0, -np.inf, -np.inf]), np.array([1.0, 2.0, np.inf]), 10.0
    )
    assert slacks == 1  # the equality is hard, the free row has no slack
    assert arrays["A"].shape == (1, 3) and arrays["G"].shape == (1, 3)
    assert list(arrays["q"]) == [0.0, 0.0, 10.0]
    solution = ElasticRescue().solve(
        hessian, rows, np.array([1.0, -np.inf, -np.inf]), np.array([1.0, 2.0, np.inf])
    )
    assert solution.z is not None and solution.z == pytest.approx([1.0, 0.0], abs=1e-6)
    assert solution.slack == pytest.approx(0.0, abs=1e-8)
