"""Each Hovershoe's heading from its direction of travel, under a foot that creeps round."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from ridempc.estimation.state import BoardEstimate
from ridempc.mpc.shoe_heading import MIN_SPEED, TIME_CONSTANT, ShoeHeading
from tests.helpers import board_estimate

DT = 0.002  # [s] the rider's tick
RNG = np.random.default_rng(0)


def _shoe(heading: float, creep: float, speed: float, noise: float) -> BoardEstimate:
    """A shoe rolling at ``speed`` [m/s] along ``heading`` [rad], its foot's toe line turned
    ``creep`` [rad] further, its velocity read with ``noise`` [m/s] on each axis."""
    velocity = speed * np.array([math.cos(heading), math.sin(heading), 0.0])
    velocity[:2] += noise * RNG.standard_normal(2)
    return BoardEstimate(
        feet=("left",),
        position=np.zeros(3),
        yaw=heading + creep,
        pitch=0.0,
        roll=0.0,
        velocity=velocity,
        yaw_rate=0.0,
    )


def _ride(filter_: ShoeHeading, seconds: float, speeds: tuple[float, float], t0: float = 0.0):
    """Two shoes turning at 0.4 rad/s, their feet creeping round at 0.012 rad/s (as on the
    circle), fed tick by tick. Returns each tick's (true headings, corrected headings)."""
    out = []
    for tick in range(int(seconds / DT)):
        t = t0 + tick * DT
        truth = (0.4 * t, 0.4 * t + 0.05)
        creep = 0.012 * t
        boards = tuple(_shoe(h, creep, v, 0.03) for h, v in zip(truth, speeds, strict=True))
        corrected = filter_(board_estimate(t, boards))
        out.append((np.array(truth), np.array([b.yaw for b in corrected.boards])))
    return out


def _error(truth: np.ndarray, heading: np.ndarray) -> np.ndarray:
    return np.abs(np.remainder(heading - truth + math.pi, 2.0 * math.pi) - math.pi)


def test_a_creeping_toe_line_is_corrected_to_the_shoes_direction_of_travel() -> None:
    filter_ = ShoeHeading(2)
    rows = _ride(filter_, 20.0, (0.8, 0.7))
    truth, heading = rows[-1]
    # 0.24 rad of creep at 20 s; the low-pass lags a ramp of 0.012 rad/s by T x 0.012
    assert _error(truth, heading).max() < 0.012 * TIME_CONSTANT + 0.01
    raw = 0.012 * 20.0
    assert filter_.slip == pytest.approx([raw, raw], abs=0.012 * TIME_CONSTANT + 0.01)


def test_below_the_least_speed_the_slip_is_held() -> None:
    filter_ = ShoeHeading(2)
    _ride(filter_, 10.0, (0.8, 0.8))
    held = filter_.slip.copy()
    _ride(filter_, 2.0, (0.5 * MIN_SPEED, 0.0), t0=10.0)
    np.testing.assert_array_equal(filter_.slip, held)


def test_a_shoe_rolling_backwards_is_read_along_its_heading() -> None:
    filter_ = ShoeHeading(1)
    for tick in range(int(5.0 / DT)):
        board = replace(_shoe(1.0, 0.1, 0.0, 0.0), velocity=-0.6 * np.array([0.54, 0.84, 0.0]))
        heading = filter_(board_estimate(tick * DT, (board,))).boards[0].yaw
    assert heading == pytest.approx(math.atan2(0.84, 0.54), abs=0.01)


def test_an_estimate_without_its_shoes_passes_through() -> None:
    estimate = board_estimate(0.0, ())
    assert ShoeHeading(2)(estimate) is estimate
