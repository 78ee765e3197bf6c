"""A push read inside the impulse band defers the deviation's handover over the push's
excursion, where the pair opts in (``ridempc.mpc.push_ride``, ``[stages.impulse]
ride_floor``); beyond the band, or with a failed plan, the ride is still handed over."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.handover import HANDOVER_DEVIATION
from ridempc.mpc.impulse import GRAVITY
from ridempc.mpc.plan import Plan
from ridempc.mpc.push_ride import RideOut, band_share, rides_push
from ridempc.mpc.stages.triggers import HandoverCheck, PushWatch, handover_triggers
from ridempc.pair_description import ImpulseStage

MASS = 10.0  # [kg] a dog-sized rider
DT = 0.002  # [s] the control tick


def _check(deviation: float, riding: bool, fallback: bool = False) -> HandoverCheck:
    zeros = np.zeros((2, 1))
    status = "failed" if fallback else "solved"
    plan = Plan(zeros, zeros[:1], np.zeros(1), status, 0.0, fallback)
    return HandoverCheck(plan, 0.0, deviation, False, True, DivergentDeviation(), riding)


def _first(check: HandoverCheck) -> str | None:
    for trigger in handover_triggers(None, None):
        reason = trigger(check)
        if reason is not None:
            return reason
    return None


def test_the_band_share_is_the_ellipse_along_and_across_the_heading() -> None:
    heading = 0.5  # [rad]
    along = np.array([math.cos(heading), math.sin(heading), 0.0])
    across = np.array([-math.sin(heading), math.cos(heading), 0.0])
    assert math.isclose(band_share(0.5 * along, heading, 1.0, 0.6), 0.5)
    assert math.isclose(band_share(0.3 * across, heading, 1.0, 0.6), 0.5)


def test_only_a_push_from_the_floor_up_to_the_band_is_ridden_out() -> None:
    assert not rides_push(0.5, None)  # the pair did not opt in
    assert not rides_push(0.1, 0.3)  # the observer's reading between pushes
    assert rides_push(0.5, 0.3)
    assert not rides_push(1.1, 0.3)  # beyond the band: the impulse trigger hands over


def test_a_ridden_push_defers_the_deviation_not_a_failed_plan() -> None:
    far = 1.5 * HANDOVER_DEVIATION
    assert "from the reference" in str(_first(_check(far, riding=False)))
    assert _first(_check(far, riding=True)) is None
    assert "MPC plan failed" in str(_first(_check(far, riding=True, fallback=True)))


def test_a_push_is_ridden_out_over_its_excursion() -> None:
    bound = HANDOVER_DEVIATION
    ride = RideOut(0.3, bound)
    assert not ride.update(0.1, 0.5 * bound)  # between pushes
    assert not ride.update(0.5, 1.5 * bound)  # already beyond the bound: not the push's
    assert ride.update(0.5, 0.5 * bound)  # a push inside the band, from within the bound
    assert ride.update(0.6, 1.3 * bound)
    assert ride.update(0.0, 1.3 * bound)  # gone from the window, the state not back yet
    assert not ride.update(0.0, 0.9 * bound)  # back within the bound: judged again
    assert not ride.update(0.1, 1.3 * bound)  # a later drift is the MPC's own
    assert ride.update(0.5, 0.5 * bound)
    assert not ride.update(1.2, 0.5 * bound)  # beyond the band: the impulse hands over


def test_the_watch_rides_out_a_push_inside_the_band() -> None:
    """A 2 N/kg push across a rider standing still for 0.15 s (0.3 m/s, half of a 0.6 m/s
    sideways band) is ridden out from 0.3 of the band (0.18 m/s, 90 ms into it) until the
    state is back within the bound; the backup riding ends it."""
    watch = PushWatch.of(ImpulseStage(band=1.0, sideways=0.6, ride_floor=0.3), MASS)
    assert watch is not None
    feet = np.tile(-GRAVITY * MASS / 4.0, (4, 1))  # the four feet carry the weight
    velocity, riding = np.zeros(3), []
    for tick in range(1000):
        time = tick * DT
        if 1.0 <= time < 1.15:
            velocity = velocity + np.array([0.0, 2.0 * DT, 0.0])
        watch.observe(_tick(time, velocity, feet))
        assert watch.reason is None  # never beyond the band
        far = 1.09 <= time < 1.8  # the push's excursion
        riding.append(watch.rides_out(1.5 * HANDOVER_DEVIATION if far else 0.5))
    ridden = np.flatnonzero(riding) * DT
    assert 1.08 <= ridden[0] <= 1.09
    assert ridden[-1] == pytest.approx(1.8 - DT)
    assert len(ridden) == round((1.8 - ridden[0]) / DT)
    watch.observe(_tick(2.0, velocity, feet, on_backup=True))
    assert watch.ride_out is not None and not watch.ride_out.active
    calm = PushWatch.of(ImpulseStage(band=1.0), MASS)  # no ride_floor: never ridden out
    assert calm is not None and not calm.rides_out(5.0)


def _tick(time: float, velocity: np.ndarray, forces: np.ndarray, on_backup: bool = False) -> Any:
    wbc = SimpleNamespace(com_velocity=velocity, forces=forces)
    estimate = SimpleNamespace(boards=[], yaw=0.0)
    sensors = SimpleNamespace(time=time)
    return cast(
        Any,
        SimpleNamespace(
            on_backup=on_backup, wbc=wbc, estimate=estimate, sensors=sensors, diagnostics={}
        ),
    )
