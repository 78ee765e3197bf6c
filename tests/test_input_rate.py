"""The plan's first input drawn towards the last one applied (ridempc.mpc.input_rate): the
merged quadratic is the sum of the two, and a heavy penalty holds the first step's forces
where they were while the rest of the plan moves freely."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc import LinearMpc, MpcProblem
from ridempc.mpc.input_rate import hold_first_input


@pytest.fixture(scope="module")
def skate() -> tuple[LinearMpc, MpcProblem]:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.5)
    x0 = mpc.reference.states_at(np.array([1.0]))[0].copy()
    x0[mpc.reference.state_names.index("com_y")] += 0.02  # off the reference: forces move
    return mpc, mpc.problem(1.0, x0)


def _cost(u: np.ndarray, reference: np.ndarray, weights: np.ndarray) -> float:
    return float(np.sum(weights * (u - reference) ** 2))


def test_the_merged_quadratic_is_the_sum_of_both(skate) -> None:
    """:math:`\\|u - \\bar u\\|^2_R + \\|u - u_p\\|^2_S - \\|u - \\tilde u\\|^2_{R+S}` is the
    same for every :math:`u_0` (it differs by a constant), and later steps are untouched."""
    _, problem = skate
    rng = np.random.default_rng(3)
    previous = problem.input_reference[0] + rng.normal(0.0, 5.0, problem.nu)
    weights = np.where(rng.random(problem.nu) < 0.5, 0.01, 0.0)
    held = hold_first_input(problem, previous, weights)
    r, u_ref = problem.input_weights, problem.input_reference[0]
    gaps = []
    for _ in range(5):
        u = u_ref + rng.normal(0.0, 10.0, problem.nu)
        both = _cost(u, u_ref, r) + _cost(u, previous, weights)
        gaps.append(both - _cost(u, held.input_reference[0], held.input_weights[0]))
    np.testing.assert_allclose(gaps, gaps[0], rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(held.input_weights[1:], np.tile(r, (problem.horizon - 1, 1)))
    np.testing.assert_array_equal(held.input_reference[1:], problem.input_reference[1:])
    assert hold_first_input(problem, previous, np.zeros(problem.nu)) is problem
    with pytest.raises(ValueError, match="non-negative"):
        hold_first_input(problem, previous, -np.ones(problem.nu))
    with pytest.raises(ValueError, match="must"):
        hold_first_input(problem, previous[:3], weights)


def test_a_heavy_penalty_holds_the_first_forces(skate) -> None:
    """With a 0.1 N tolerance on the deck forces the first step's forces stay within 0.5 N
    of the last ones though the plan without it moves them by several newtons; the QP
    built for the plain problem solves the held one (same pattern, new values)."""
    mpc, problem = skate
    qp = mpc.build_qp(problem)
    free = qp.solve(problem)
    forces = mpc.reference.force_index.ravel()
    previous = free.first_input.copy()
    previous[forces] = problem.input_reference[0, forces]
    assert np.abs(free.first_input[forces] - previous[forces]).max() > 2.0
    weights = np.zeros(problem.nu)
    weights[forces] = 1.0 / 0.1**2
    held = qp.solve(hold_first_input(problem, previous, weights))
    assert held.status == "solved"
    assert np.abs(held.first_input[forces] - previous[forces]).max() < 0.5
    # the change is put off, not refused: the second step's forces move as before
    assert np.abs(held.inputs[1, forces] - previous[forces]).max() > 1.0
