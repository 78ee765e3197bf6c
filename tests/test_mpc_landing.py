"""A drop's landing ridden flat-footed: each foot's load centred on its shoe (mpc/landing.py)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.estimation.state import EstimatedState
from ridempc.mpc.drop import SINK_SPEED
from ridempc.mpc.flight import LAND_TICKS, DropFlight
from ridempc.mpc.landing import LANDING_S, LandingLoads
from ridempc.mpc.plan_book import PlanBook
from ridempc.mpc.stages.feet_targets import FootTargets
from ridempc.mpc.stages.wbc_targets import TargetsFromPlan
from ridempc.mpc.state_map import PlanarFrame
from ridempc.trajopt.schedule import Contact
from tests.helpers import board_estimate

DT = 0.002  # [s] the whole-body QP's tick
CONTACT_FOOT = (0, 0, 1, 1)  # Cassie's toe lines: front and back site of each foot
# [N] a plan braking its shoes: each foot's load on its heel (front, back per foot)
HEELS = np.array([[1.0, 0.0, 8.0], [-3.0, 2.0, 205.0], [0.5, 0.0, 10.0], [-2.0, -1.0, 164.0]])


def _estimate(t: float, feet_vz: float, drop: float = 0.0) -> EstimatedState:
    """Both feet sinking at ``feet_vz`` [m/s], ``drop`` [m] below where they started."""
    velocity = np.zeros((2, 3))
    velocity[:, 2] = feet_vz
    return replace(
        board_estimate(t, ()),
        base_position=np.array([0.0, 0.0, 1.0 - drop]),
        base_velocity=np.array([0.5, 0.0, 0.0]),
        foot_position=np.array([[0.0, 0.1, -drop], [0.0, -0.1, -drop]]),
        foot_velocity=velocity,
    )


def _landed_flight(at: float, depth: float = 0.0, flight: DropFlight | None = None) -> DropFlight:
    """A flight from a drop ``at - 0.1`` s whose feet sank ``depth`` [m] and stopped,
    landing at ``at`` [s] (on ``flight``, or a new one)."""
    flight = DropFlight() if flight is None else flight
    flight.update(True, _estimate(at - 0.1, 0.0))
    flight.update(False, _estimate(at - 0.05, -2.0 * SINK_SPEED, 0.5 * depth))
    start = at - (LAND_TICKS - 1) * DT
    for k in range(LAND_TICKS):
        flight.update(False, _estimate(start + k * DT, 0.0, depth))
    assert not flight.flying
    return flight


def test_the_flight_records_its_landing_and_its_depth() -> None:
    """The landing's time, and the fall as the feet's height lost from the drop to it."""
    flight = _landed_flight(0.1, depth=0.076)
    assert flight.landed == pytest.approx(0.1)
    assert flight.depth == pytest.approx(0.076)
    assert flight.depths == [flight.depth]
    flight.reset()
    assert flight.landed is None
    assert flight.depth is None


def test_a_shallow_landing_keeps_the_plans_loads() -> None:
    """A fall shallower than ``depth`` (the deck clears the edge at any pitch) is ridden on
    the plan's centre of pressure; a deeper one flat-footed."""
    depth = 0.05
    shallow = LandingLoads(_landed_flight(0.1, depth=0.041), CONTACT_FOOT, LANDING_S, depth)
    assert shallow(HEELS, 0.15) is HEELS
    deep = LandingLoads(_landed_flight(0.1, depth=0.076), CONTACT_FOOT, LANDING_S, depth)
    out = deep(HEELS, 0.15)
    np.testing.assert_allclose(out[0], out[1])


def test_the_landing_ends_at_the_next_take_off() -> None:
    """A drop within the window ends the landing's loads (no foot stands in a flight);
    the next landing's own depth then decides."""
    flight = _landed_flight(0.1, depth=0.076)
    loads = LandingLoads(flight, CONTACT_FOOT, LANDING_S, 0.05)
    assert loads.landing(0.15)
    flight.update(True, _estimate(0.16, 0.0, 0.076))
    assert flight.flying
    assert not loads.landing(0.17)
    _landed_flight(0.25, depth=0.03, flight=flight)  # the next: a shallow one
    assert not loads.landing(0.26)


def test_no_landing_no_change() -> None:
    """Before any flight, the plan's centre of pressure is applied as planned."""
    loads = LandingLoads(DropFlight(), CONTACT_FOOT)
    assert loads(HEELS, 1.0) is HEELS


def test_a_landed_foot_loads_its_sites_evenly() -> None:
    """Within the window each foot's total force is kept and shared evenly between its
    sites (no pitching moment on its platform); after it, the plan's split again."""
    loads = LandingLoads(_landed_flight(0.1), CONTACT_FOOT)
    out = loads(HEELS, 0.1 + 0.5 * LANDING_S)
    np.testing.assert_allclose(out[0], out[1])
    np.testing.assert_allclose(out[2], out[3])
    np.testing.assert_allclose(out[0] + out[1], HEELS[0] + HEELS[1])
    np.testing.assert_allclose(out[2] + out[3], HEELS[2] + HEELS[3])
    assert loads(HEELS, 0.1 + LANDING_S + DT) is HEELS


def test_the_whole_body_targets_carry_the_landed_split() -> None:
    """The targets' site forces are the landing's (each foot's mean) within its window."""
    rates = ("velocity", "acceleration", "angular_velocity", "angular_acceleration")
    wanted = SimpleNamespace(
        site_forces=HEELS,
        forces=np.zeros((2, 3)),
        position=np.array([0.0, 0.0, 0.9]),
        orientation=np.array([1.0, 0.0, 0.0, 0.0]),
        **{name: np.zeros(3) for name in rates},
    )
    standing = FootTargets(np.ones(2), np.zeros((2, 3)), np.zeros((2, 3)), None)
    book = PlanBook(None)
    book.plan, book.time, book.frame = cast(Any, object()), 0.1, PlanarFrame(0.0)
    flight = _landed_flight(0.1)
    targets = TargetsFromPlan(
        cast(Any, lambda plan, frame, age: wanted),
        cast(Any, lambda support, t_ref, estimate, frame: standing),
        flight,
        None,
        True,
        LandingLoads(flight, CONTACT_FOOT),
    )
    estimate = cast(Any, SimpleNamespace(boards=()))
    support = (Contact.BOARD, Contact.BOARD)
    out = targets(book, support, 0.0, estimate, 0.15)
    assert out.site_forces is not None
    np.testing.assert_allclose(out.site_forces[1], 0.5 * (HEELS[0] + HEELS[1]))
    later = targets(book, support, 0.0, estimate, 0.1 + 2.0 * LANDING_S)
    assert later.site_forces is not None
    np.testing.assert_array_equal(later.site_forces, HEELS)


def test_a_window_must_be_positive_and_a_depth_not_negative() -> None:
    with pytest.raises(ValueError, match="window"):
        LandingLoads(DropFlight(), CONTACT_FOOT, 0.0)
    with pytest.raises(ValueError, match="depth"):
        LandingLoads(DropFlight(), CONTACT_FOOT, LANDING_S, -0.01)
