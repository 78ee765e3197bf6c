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


def _estimate(t: float, feet_vz: float) -> EstimatedState:
    velocity = np.zeros((2, 3))
    velocity[:, 2] = feet_vz
    return replace(
        board_estimate(t, ()),
        base_position=np.array([0.0, 0.0, 1.0]),
        base_velocity=np.array([0.5, 0.0, 0.0]),
        foot_position=np.array([[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]]),
        foot_velocity=velocity,
    )


def _landed_flight(at: float) -> DropFlight:
    """A flight from a drop at 0 s whose feet sank and stopped, landing at ``at`` [s]."""
    flight = DropFlight()
    flight.update(True, _estimate(0.0, 0.0))
    flight.update(False, _estimate(0.05, -2.0 * SINK_SPEED))
    start = at - (LAND_TICKS - 1) * DT
    for k in range(LAND_TICKS):
        flight.update(False, _estimate(start + k * DT, 0.0))
    assert not flight.flying
    return flight


def test_the_flight_records_its_landing() -> None:
    flight = _landed_flight(0.1)
    assert flight.landed == pytest.approx(0.1)
    flight.reset()
    assert flight.landed is None


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


def test_a_window_must_be_positive() -> None:
    with pytest.raises(ValueError, match="window"):
        LandingLoads(DropFlight(), CONTACT_FOOT, 0.0)
