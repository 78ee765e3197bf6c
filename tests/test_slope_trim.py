"""The slope's speed trim (ridempc/mpc/slope_trim.py): the integral alone, and the reference
it lays over, without a ride."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import cast

import numpy as np
import pytest

from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.slope_trim import (
    BAND,
    GATE,
    HOLD,
    LIMIT,
    TIME_CONSTANT,
    SlopeSpeedTrim,
    SlopeTrim,
)

DOWN_13 = [-math.radians(13.0)] * 2  # [rad] both shoes on slope-down-13's incline
STEP = 1.0 / 30.0  # [s] the MPC's tick


def ride(trim: SlopeSpeedTrim, seconds: float, wanted: float, speed: float, slopes, **kw):
    """Feed ``trim`` a steady error for ``seconds`` from its last time; its last value."""
    start = trim._time if trim._time is not None else 0.0
    value = 0.0
    for k in range(1, round(seconds / STEP) + 1):
        value = trim.update(start + k * STEP, wanted, speed, slopes, **kw)
    return value


def test_level_ground_leaves_the_reference_alone():
    trim = SlopeSpeedTrim()
    level = [0.5 * GATE, 0.5 * GATE]
    assert ride(trim, 3.0, 0.5, 0.34, level) == 0.0
    assert trim.per_slope == 0.0


def on_the_slope(trim: SlopeSpeedTrim, slopes=DOWN_13) -> None:
    """Ride ``trim`` onto ``slopes`` with no speed error until it holds them for a slope."""
    trim.update(0.0 if trim._time is None else trim._time, 0.5, 0.5, slopes)
    ride(trim, HOLD + STEP, 0.5, 0.5, slopes)


def test_a_slope_read_for_less_than_its_hold_is_none():
    trim = SlopeSpeedTrim()
    trim.update(0.0, 0.5, 0.4, DOWN_13)
    assert ride(trim, HOLD - 2 * STEP, 0.5, 0.4, DOWN_13) == 0.0  # a step's edge, a bump
    assert ride(trim, STEP, 0.5, 0.4, [0.0, 0.0]) == 0.0
    assert trim.per_slope == 0.0


def test_a_steady_error_on_a_slope_is_integrated_at_its_rate():
    trim = SlopeSpeedTrim()
    on_the_slope(trim)
    value = ride(trim, 1.0, 0.5, 0.4, DOWN_13)
    # (v_cmd - v) / T over 1 s, whatever the slope's steepness
    assert value == pytest.approx(0.1 * 1.0 / TIME_CONSTANT, rel=1e-9)
    assert trim.per_slope == pytest.approx(value / math.sin(math.radians(13.0)))


def test_the_trim_is_bounded():
    trim = SlopeSpeedTrim()
    on_the_slope(trim)
    assert ride(trim, 30.0, 0.5, 0.3, DOWN_13) == pytest.approx(LIMIT)


def test_transients_and_the_backups_ride_are_not_integrated():
    trim = SlopeSpeedTrim()
    on_the_slope(trim)
    assert ride(trim, 1.0, 0.5, 0.5 - 1.2 * BAND, DOWN_13) == 0.0  # a crest's run-off
    assert ride(trim, 1.0, 0.5, 0.4, DOWN_13, riding=False) == 0.0


def test_the_trim_goes_with_the_slope_and_comes_back_with_it():
    trim = SlopeSpeedTrim()
    on_the_slope(trim)
    held = ride(trim, 1.0, 0.5, 0.4, DOWN_13)
    assert ride(trim, 0.1, 0.5, 0.6, [0.0, 0.0]) == 0.0  # the slope's end: gone at once
    on_the_slope(trim)  # the same slope again, held for its hold
    assert trim.value == pytest.approx(held)
    # half the slope's sine, half the trim (a gentler slope's pull)
    gentle = [math.asin(0.5 * math.sin(DOWN_13[0]))] * 2
    assert ride(trim, STEP, 0.5, 0.5, gentle) == pytest.approx(0.5 * held)


def test_at_rest_there_is_no_trim():
    trim = SlopeSpeedTrim()
    on_the_slope(trim)
    ride(trim, 1.0, 0.5, 0.4, DOWN_13)
    assert ride(trim, STEP, 0.0, 0.0, DOWN_13) == 0.0


def test_bad_settings_are_refused():
    with pytest.raises(ValueError, match="time_constant"):
        SlopeSpeedTrim(time_constant=0.0)


def test_the_reference_moves_faster_from_its_first_node():
    names = {"com_x": 0, "com_y": 1, "vx": 2, "vy": 3}
    layout = cast(StateLayout, SimpleNamespace(names=names))
    columns = [(4, 5, 6, 7), (8, 9, 10, 11)]  # per shoe: x, y, heading, speed
    shaper = SlopeTrim(layout, columns)
    nodes, dt, trim = 13, 1.0 / 30.0, 0.2
    states = np.zeros((nodes, 12))
    states[:, 2] = states[:, 7] = states[:, 11] = 0.5  # riding at 0.5 m/s
    states[:, 6] = states[:, 10] = 0.1  # both shoes heading 0.1 rad
    out = shaper.lay_over(states, trim, dt)
    ahead = trim * dt * np.arange(nodes)
    np.testing.assert_allclose(out[0], states[0])  # the estimate's node is the library's
    np.testing.assert_allclose(out[1:, 2], 0.5 + trim * math.cos(0.1))
    np.testing.assert_allclose(out[1:, 3], trim * math.sin(0.1))
    np.testing.assert_allclose(out[1:, 7], 0.7)
    np.testing.assert_allclose(out[:, 0], ahead * math.cos(0.1))
    np.testing.assert_allclose(out[:, 4], ahead * math.cos(0.1))
    np.testing.assert_allclose(out[:, 9], ahead * math.sin(0.1))
    np.testing.assert_allclose(states[:, 0], 0.0)  # the input is not changed
