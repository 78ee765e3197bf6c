"""The followed ground's rate's lag (``[mpc] ground_rate_filter``, ``ridempc.mpc.state_map``): a
deck that swings up a slope moves the followed ground's rate as much as its lag lets through,
and the followed height keeps up with the incline whatever that lag."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from ridempc.estimation.state import BoardEstimate
from ridempc.mpc.state_map import GROUND_FILTER_S, StateMap
from ridempc.pair_description import load_pair_description
from ridempc.robots import load_robot
from ridempc.robots.pinocchio_model import build_pinocchio_robot

SLOPE = math.radians(10.0)  # [rad] the Segway's library incline
SPEED = 1.0  # [m/s] ridden up it
SWING_HZ = 5.5  # [Hz] the firmware's pitch swing measured on it (slope-up-10, seed 7)
SWING = 0.4  # [m/s] the board's speed swing in it (1.27 -> 0.42 m/s and back)


@pytest.fixture(scope="module")
def cassie_model():
    return build_pinocchio_robot(load_robot("cassie"))


def _rate_swing(model, ground_rate_filter: float) -> tuple[float, float, float]:
    """The followed ground's rate [m/s] over the last second of 8 s up the slope at 500 Hz,
    the board's speed swinging: its mean and its peak-to-peak; and how far the followed
    height trails the deck's at the end [m]."""
    state_map = StateMap(
        model, ("com_z",), {}, base="pelvis", ground_rate_filter=ground_rate_filter
    )
    rates = []
    for k in range(4000):
        t = k / 500.0
        speed = SPEED + 0.5 * SWING * math.sin(2.0 * math.pi * SWING_HZ * t)
        velocity = speed * np.array([math.cos(SLOPE), 0.0, math.sin(SLOPE)])
        height = SPEED * math.sin(SLOPE) * t
        board = BoardEstimate(("f",), np.array([0.0, 0.0, height]), 0.0, 0.0, 0.0, velocity, 0.0)
        followed = state_map.follow_ground(SimpleNamespace(time=t, boards=(board,)))
        rates.append(state_map.ground_rate)
    last = np.array(rates[-500:])
    return float(np.mean(last)), float(np.ptp(last)), height - followed


def test_a_slow_ground_keeps_the_decks_swing_out_and_its_climb_in(cassie_model) -> None:
    """Up 10 deg at 1 m/s the deck climbs at v sin(a) = 0.17 m/s and its swing moves that by
    0.4 sin(a) = 0.07 m/s peak to peak: the default lag (0.1 s, a Hovershoe's step) passes about a
    quarter of the swing, the Segway's 1 s about a thirtieth, and both follow the climb; the
    height trails the deck by the default lag's climb, v sin(a) x 0.1 s = 1.7 cm, with both."""
    climb = SPEED * math.sin(SLOPE)
    swing = SWING * math.sin(SLOPE)
    fast_mean, fast_swing, fast_lag = _rate_swing(cassie_model, GROUND_FILTER_S)
    slow_mean, slow_swing, slow_lag = _rate_swing(cassie_model, 1.0)
    assert fast_mean == pytest.approx(climb, abs=0.005)
    assert slow_mean == pytest.approx(climb, abs=0.01)
    assert fast_swing > 0.25 * swing
    assert slow_swing < 0.05 * swing
    for lag in (fast_lag, slow_lag):
        assert lag == pytest.approx(climb * GROUND_FILTER_S, abs=0.002)


def test_the_segway_follows_the_ground_slowly_and_the_others_as_before() -> None:
    assert load_pair_description("cassie", "segway").mpc.ground_rate_filter == 1.0
    assert load_pair_description("cassie", "hovershoes").mpc.ground_rate_filter is None
