"""A drop ridden by the whole-body QP, the feet following the platforms (mpc/flight.py)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ridempc.estimation.state import EstimatedState
from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.drop import SINK_SPEED, DropDetector
from ridempc.mpc.flight import (
    EXTEND_SPEED,
    LAND_TICKS,
    LONGEST_S,
    MAX_EXTENSION,
    DropFlight,
)
from ridempc.mpc.plan import Plan
from ridempc.mpc.stages.triggers import DropWatch, HandoverCheck, handover_triggers
from ridempc.pair_description import load_pair_description
from tests.helpers import board_estimate

DT = 0.002  # [s] the whole-body QP's tick
FEET = np.array([[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]])  # [m] under a base 1 m up
BASE = np.array([0.0, 0.0, 1.0])


def _estimate(t: float, feet_vz: float, base_vz: float = 0.0, drop: float = 0.0) -> EstimatedState:
    """Both feet sinking at ``feet_vz`` [m/s], everything ``drop`` [m] down."""
    down = np.array([0.0, 0.0, drop])
    velocity = np.zeros((2, 3))
    velocity[:, 2] = feet_vz
    return replace(
        board_estimate(t, ()),
        base_position=BASE - down,
        base_velocity=np.array([0.5, 0.0, base_vz]),
        foot_position=FEET - down,
        foot_velocity=velocity,
    )


def test_no_drop_no_flight() -> None:
    flight = DropFlight()
    assert not any(flight.update(False, _estimate(k * DT, -1.0)) for k in range(50))
    assert not flight.flying


def test_a_flight_lasts_from_the_drop_to_the_feet_stopped() -> None:
    """The flight ends once every foot has stopped sinking for LAND_TICKS ticks, and not
    before the feet have sunk (a landing ends a fall)."""
    flight = DropFlight()
    assert flight.update(True, _estimate(0.0, 0.0))
    for k in range(20):  # the feet not yet sinking: no landing
        assert flight.update(False, _estimate((k + 1) * DT, 0.0))
    assert flight.update(False, _estimate(0.05, -2.0 * SINK_SPEED))
    stopped = [flight.update(False, _estimate(0.05 + (k + 1) * DT, 0.0)) for k in range(LAND_TICKS)]
    assert stopped == [True] * (LAND_TICKS - 1) + [False]
    assert not flight.too_long(1.0)
    assert flight.starts == [0.0]
    flight.reset()
    assert flight.starts == []


def test_one_foot_still_sinking_is_no_landing() -> None:
    flight = DropFlight()
    flight.update(True, _estimate(0.0, -2.0 * SINK_SPEED))
    one = _estimate(DT, 0.0)
    one.foot_velocity[0, 2] = -2.0 * SINK_SPEED
    assert all(flight.update(False, replace(one, time=k * DT)) for k in range(1, 3 * LAND_TICKS))


def test_a_flight_longer_than_any_step_is_told() -> None:
    flight = DropFlight()
    flight.update(True, _estimate(0.0, -1.0))
    assert not flight.too_long(LONGEST_S - DT)
    assert flight.too_long(LONGEST_S + DT)


def test_the_feet_follow_the_base_down_and_reach_after_their_platforms() -> None:
    """Held under the base where they were at the drop, reaching down at EXTEND_SPEED up to
    MAX_EXTENSION, falling with the rider (feedforward -g)."""
    flight = DropFlight()
    flight.update(True, _estimate(0.0, -1.0))
    t = 0.5 * MAX_EXTENSION / EXTEND_SPEED
    now = _estimate(t, -1.0, base_vz=-0.3, drop=0.02)
    position, velocity, acceleration = flight.swing(now)
    np.testing.assert_allclose(position, FEET - [0.0, 0.0, 0.02 + EXTEND_SPEED * t])
    np.testing.assert_allclose(velocity, np.tile([0.5, 0.0, -0.3 - EXTEND_SPEED], (2, 1)))
    np.testing.assert_allclose(acceleration, np.tile([0.0, 0.0, -9.81], (2, 1)))
    position, velocity, _ = flight.swing(replace(now, time=1.0))
    np.testing.assert_allclose(position, FEET - [0.0, 0.0, 0.02 + MAX_EXTENSION])
    np.testing.assert_allclose(velocity[:, 2], -0.3)


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError, match="extend_speed"):
        DropFlight(extend_speed=0.0)
    with pytest.raises(ValueError, match="max_extension"):
        DropFlight(max_extension=-0.1)


def test_the_hovershoes_pair_rides_its_drops() -> None:
    assert load_pair_description("cassie", "hovershoes").stages.flight is not None
    assert load_pair_description("cassie", "segway").stages.flight is None


def test_the_flight_takes_the_drop_s_place_among_the_triggers() -> None:
    """While the drop is in the air only a flight longer than any step's hands over."""
    flight = DropFlight(DropWatch(DropDetector()))
    triggers = handover_triggers(flight.watch, None, flight)
    assert flight in triggers and flight.watch not in triggers
    flight.update(True, _estimate(0.0, -1.0))
    calm = HandoverCheck(
        Plan(np.zeros((2, 1)), np.zeros((1, 1)), np.zeros(1), "solved", 0.0, False),
        0.0,
        0.0,
        False,
        True,
        DivergentDeviation(),
    )
    assert flight(calm) is None
    flight._now = LONGEST_S + DT
    assert "a drop" in str(flight(calm))
