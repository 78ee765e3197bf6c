"""A push read inside the impulse band defers the deviation's handover until the rider
has settled, where the pair opts in (``ridempc.mpc.push_ride``, ``[stages.impulse]
ride_floor``); beyond the band, or with a failed plan, the ride is still handed over."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.handover import HANDOVER_DEVIATION, RETURN_DEVIATION
from ridempc.mpc.impulse import GRAVITY, ImpulseObserver, ImpulseTrigger
from ridempc.mpc.plan import Plan
from ridempc.mpc.push_ride import RideOut, band_share, rides_push
from ridempc.mpc.stages.triggers import HandoverCheck, PushWatch, handover_triggers

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
    assert not rides_push(0.1, 0.25)  # the observer's idle residual
    assert rides_push(0.5, 0.25)
    assert not rides_push(1.1, 0.25)  # beyond the band: the impulse trigger hands over


def test_a_ridden_push_defers_the_deviation_not_a_failed_plan() -> None:
    far = 1.5 * HANDOVER_DEVIATION
    assert "from the reference" in str(_first(_check(far, riding=False)))
    assert _first(_check(far, riding=True)) is None
    assert "MPC plan failed" in str(_first(_check(far, riding=True, fallback=True)))


def test_a_push_is_ridden_out_until_the_rider_has_settled() -> None:
    ride = RideOut(0.25)
    assert not ride.update(0.1, 2.0 * RETURN_DEVIATION)  # idle: no push
    assert ride.update(0.5, 2.0 * RETURN_DEVIATION)  # a push inside the band
    assert ride.update(0.0, 3.0 * RETURN_DEVIATION)  # gone from the window, not settled
    assert not ride.update(0.0, 0.9 * RETURN_DEVIATION)  # settled: judged again
    assert ride.update(0.5, 0.0)
    assert not ride.update(1.2, 2.0 * RETURN_DEVIATION)  # beyond the band: handed over


def test_the_watch_rides_out_a_push_inside_the_band() -> None:
    """A 2 N/kg push across a rider standing still for 0.15 s (0.3 m/s, half of a 0.6 m/s
    sideways band) is ridden out from a quarter of the band (0.15 m/s, 75 ms into it) until
    the rider has settled; the backup riding ends it."""
    watch = PushWatch(ImpulseObserver(MASS), ImpulseTrigger(1.0, 0.6), ride_floor=0.25)
    feet = np.tile(-GRAVITY * MASS / 4.0, (4, 1))  # the four feet carry the weight
    velocity, riding = np.zeros(3), []
    for tick in range(1000):
        time = tick * DT
        if 1.0 <= time < 1.15:
            velocity = velocity + np.array([0.0, 2.0 * DT, 0.0])
        watch.observe(_tick(time, velocity, feet))
        assert watch.reason is None  # never beyond the band
        riding.append(watch.rides_out(deviation=2.0 if time < 1.8 else 0.5))
    ridden = np.flatnonzero(riding) * DT
    assert 1.07 <= ridden[0] <= 1.08
    assert ridden[-1] == pytest.approx(1.8 - DT)  # settled at 1.8 s
    assert len(ridden) == round((1.8 - ridden[0]) / DT)
    watch.observe(_tick(2.0, velocity, feet, on_backup=True))
    assert watch.ride_out is not None and not watch.ride_out.active
    assert not PushWatch(ImpulseObserver(MASS), ImpulseTrigger(1.0)).rides_out(5.0)


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
