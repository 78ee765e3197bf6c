"""The low-pass on the MPC's forces (ridempc.mpc.force_filter)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc.mpc.force_filter import ForceFilter
from ridempc.mpc.pairs import load_mpc_pair


def test_the_first_solve_passes_through_and_a_step_rises_as_a_first_order_lag() -> None:
    tau, dt = 0.084, 0.03
    low_pass = ForceFilter(tau)
    np.testing.assert_array_equal(low_pass(np.array([0.0, 80.0]), 0.0), [0.0, 80.0])
    step = np.array([50.0, 20.0])
    for k in range(1, 8):
        out = low_pass(step, k * dt)
        rise = 1.0 - math.exp(-k * dt / tau)
        np.testing.assert_allclose(out, [0.0, 80.0] + rise * (step - [0.0, 80.0]), rtol=1e-12)
    assert low_pass(step, 7 * dt) == pytest.approx(out)  # no time passed: no change


def test_a_new_input_size_restarts_the_filter() -> None:
    low_pass = ForceFilter(0.1)
    low_pass(np.zeros(3), 0.0)
    np.testing.assert_array_equal(low_pass(np.ones(4), 0.03), np.ones(4))


@pytest.mark.parametrize("tau", [0.0, -0.1, math.inf, math.nan])
def test_a_time_constant_that_is_not_positive_is_refused(tau: float) -> None:
    with pytest.raises(ValueError, match="time constant"):
        ForceFilter(tau)


def test_only_the_hovershoes_low_pass_their_forces() -> None:
    """The dog's feet swing (a filter would hold force on a lifted foot); on the Segway
    the same filter quietened Cassie's toes but velocity-steps fell at 15.38 s (seed 0)."""
    assert load_mpc_pair("cassie", "hovershoes").force_time_constant == pytest.approx(0.042)
    assert load_mpc_pair("cassie", "segway").force_time_constant is None
    assert load_mpc_pair("cyberdog2", "skateboard").force_time_constant is None
