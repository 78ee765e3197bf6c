"""The MPC QP's rows held in one OSQP class: each rewrite is the same constraint, only
the rows that must change class change, and a QP whose rows keep their class is solved
as before."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.row_classes import (
    BAND,
    EQUALITY,
    INEQUALITY,
    LOOSE,
    WIDE,
    RowClasses,
)
from tests.helpers import osqp_tight

INF = np.inf


def _classes() -> RowClasses:
    """Four rows of one stored value each (an identity): equality, inequality, loose,
    equality."""
    lower = np.array([0.0, -1.0, -INF, 2.0])
    upper = np.array([0.0, 1.0, INF, 2.0])
    return RowClasses(lower, upper, np.arange(4))


def test_the_set_up_classes_are_osqps() -> None:
    classes = _classes()
    assert classes.held.tolist() == [EQUALITY, INEQUALITY, LOOSE, EQUALITY]
    assert RowClasses.wanted(np.array([0.0]), np.array([0.5e-4])).tolist() == [EQUALITY]


def test_unchanged_classes_pass_the_arrays_through() -> None:
    classes = _classes()
    values, lower, upper = (
        np.ones(4),
        np.array([1.0, -2.0, -INF, 3.0]),
        np.array([1.0, 0.0, INF, 3.0]),
    )
    out = classes.hold(values, lower, upper)
    assert out[0] is values and out[1] is lower and out[2] is upper and classes.switches == 0


def test_a_free_row_held_as_an_equality_is_a_zero_row() -> None:
    classes = _classes()
    values, lower, upper = classes.hold(
        np.ones(4), np.array([0.0, -1.0, -INF, -INF]), np.array([0.0, 1.0, INF, INF])
    )
    assert values.tolist() == [1.0, 1.0, 1.0, 0.0]
    assert (lower[3], upper[3]) == (0.0, 0.0) and classes.switches == 0


def test_a_free_row_held_as_an_inequality_gets_wide_bounds() -> None:
    classes = _classes()
    _, lower, upper = classes.hold(
        np.ones(4), np.array([0.0, -INF, -INF, 2.0]), np.array([0.0, INF, INF, 2.0])
    )
    assert (lower[1], upper[1]) == (-WIDE, WIDE) and classes.held[1] == INEQUALITY


def test_an_equality_held_as_an_inequality_is_a_narrow_band() -> None:
    classes = _classes()
    _, lower, upper = classes.hold(
        np.ones(4), np.array([0.0, 0.3, -INF, 2.0]), np.array([0.0, 0.3, INF, 2.0])
    )
    assert lower[1] == pytest.approx(0.3 - BAND) and upper[1] == pytest.approx(0.3 + BAND)
    assert classes.wanted(lower, upper)[1] == INEQUALITY and classes.switches == 0


def test_only_the_rows_that_must_change_class_do() -> None:
    classes = _classes()
    # the loose row gets a bound, the first equality an inequality: both must change
    _, lower, upper = classes.hold(
        np.ones(4), np.array([-1.0, -1.0, 0.0, 2.0]), np.array([1.0, 1.0, 1.0, 2.0])
    )
    assert classes.held.tolist() == [INEQUALITY, INEQUALITY, INEQUALITY, EQUALITY]
    assert classes.switches == 1
    assert lower.tolist() == [-1.0, -1.0, 0.0, 2.0] and upper.tolist() == [1.0, 1.0, 1.0, 2.0]


@pytest.mark.parametrize("seed", [0, 1])
def test_the_held_rows_keep_the_optimum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, m = 8, 6
    root = rng.normal(size=(n, n))
    p, q = root @ root.T + 0.1 * np.eye(n), 5.0 * rng.normal(size=n)
    a = rng.normal(size=(m, n))
    # held: equality, equality, inequality, inequality, inequality, equality
    set_up_lower = np.array([0.1, 0.0, -1.0, -1.0, -1.0, 0.2])
    set_up_upper = np.array([0.1, 0.0, 1.0, 1.0, 1.0, 0.2])
    rows, cols = np.nonzero(np.ones((m, n)))  # dense, row-major: each value's row
    classes = RowClasses(set_up_lower, set_up_upper, rows)
    # asked for: equality, free, free, equality, inequality, equality
    lower = np.array([0.3, -INF, -INF, 0.4, -0.5, -0.1])
    upper = np.array([0.3, INF, INF, 0.4, 0.5, -0.1])
    values, held_lower, held_upper = classes.hold(a[rows, cols], lower, upper)
    held_a = np.zeros_like(a)
    held_a[rows, cols] = values
    assert classes.switches == 0
    exact = osqp_tight(p, q, a, lower, upper)
    held = osqp_tight(p, q, held_a, held_lower, held_upper)
    assert held == pytest.approx(exact, abs=10 * BAND * np.abs(exact).max())


def test_a_quadruped_qp_solves_alike_with_and_without_held_classes() -> None:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)
    x0 = mpc.reference.sample(-1.0, 0, 1.0).states[0] + 0.01
    problems = [mpc.problem(t, x0) for t in np.arange(0.0, 0.8, 0.1)]  # feet lift, land
    plans = {}
    for held in (True, False):
        qp = mpc.build_qp(problems[0], row_classes=held)
        plans[held] = [qp.solve(problem) for problem in problems]
        assert qp.failures == 0
        assert not held or qp.row_classes is not None and 0 < qp.row_classes.switches < 8
    tolerance = mpc.build_qp(problems[0])._scale[-mpc.model.nu :]
    for with_held, without in zip(plans[True], plans[False], strict=True):
        assert np.max(np.abs(with_held.first_input - without.first_input) / tolerance) < 1e-2
