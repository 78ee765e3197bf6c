"""A push read inside the impulse band defers the deviation's handover where the pair opts
in (``ridempc.mpc.push_ride``, ``[stages.impulse] ride_floor``); beyond the band, or with
a failed plan, the ride is still handed over."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any, cast

import numpy as np

from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.handover import HANDOVER_DEVIATION
from ridempc.mpc.impulse import GRAVITY, ImpulseObserver, ImpulseTrigger
from ridempc.mpc.plan import Plan
from ridempc.mpc.push_ride import band_share, rides_push
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


def test_the_watch_reads_a_push_inside_the_band_while_it_is_in_the_window() -> None:
    """A 2 N/kg push across a rider standing still for 0.15 s (0.3 m/s, half of a 0.6 m/s
    sideways band) is ridden from a quarter of the band (0.15 m/s, 75 ms into it) until the
    window has let it go."""
    watch = PushWatch(ImpulseObserver(MASS), ImpulseTrigger(1.0, 0.6), ride_floor=0.25)
    feet = np.tile(-GRAVITY * MASS / 4.0, (4, 1))  # the four feet carry the weight
    velocity, riding = np.zeros(3), []
    for tick in range(1000):
        time = tick * DT
        if 1.0 <= time < 1.15:
            velocity = velocity + np.array([0.0, 2.0 * DT, 0.0])
        wbc = SimpleNamespace(com_velocity=velocity, forces=feet)
        estimate = SimpleNamespace(boards=[], yaw=0.0)
        sensors = SimpleNamespace(time=time)
        watch.observe(
            cast(
                Any,
                SimpleNamespace(
                    on_backup=False, wbc=wbc, estimate=estimate, sensors=sensors, diagnostics={}
                ),
            )
        )
        assert watch.reason is None  # never beyond the band
        riding.append(watch.riding)
    ridden = np.flatnonzero(riding) * DT
    assert 1.07 <= ridden[0] <= 1.08
    assert 1.4 <= ridden[-1] < 1.6  # it leaves the 0.4 s window
