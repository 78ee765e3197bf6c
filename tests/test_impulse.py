"""The external-impulse observer and its trigger (``ridempc.mpc.impulse``), on made-up
rides of a point mass sampled at the control loop's 500 Hz, and a Pinocchio model's
centre-of-mass velocity."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc.mpc.impulse import GRAVITY, WINDOW_S, ImpulseObserver, ImpulseTrigger

STEP = 1.0 / 500.0  # [s] the control tick
MASS = 32.0  # [kg] a Cassie-sized rider
BAND = 0.3  # [m/s]


def _ride(
    contact: list[np.ndarray], push: list[np.ndarray], observer: ImpulseObserver
) -> tuple[np.ndarray, float]:
    """A point mass moved by ``contact`` (what the rider commands and gets) and ``push``
    (from outside) [N] each tick, plus gravity; the observer told only the contact forces.
    Returns the centre of mass's last velocity and the observer's peak."""
    velocity = np.zeros(3)
    for k, (f, p) in enumerate(zip(contact, push, strict=True)):
        observer.update(k * STEP, velocity, f)
        velocity = velocity + ((f + p) / MASS + GRAVITY) * STEP
    return velocity, observer.peak


def _standing(ticks: int) -> list[np.ndarray]:
    return [np.array([0.0, 0.0, MASS * 9.81])] * ticks


def test_a_push_reads_as_its_impulse() -> None:
    """A 2 N/kg push for 0.2 s towards 135 deg on a rider standing still: 0.4 m/s, in its
    direction."""
    ticks, start, length = 1500, 1000, 100  # 3 s; the push at 2 s for 0.2 s
    direction = np.array([math.cos(math.radians(135.0)), math.sin(math.radians(135.0)), 0.0])
    push = [
        2.0 * MASS * direction if start <= k < start + length else np.zeros(3) for k in range(ticks)
    ]
    observer = ImpulseObserver(MASS)
    velocity = np.zeros(3)
    read = []
    for k in range(ticks):
        observer.update(k * STEP, velocity, _standing(1)[0])
        read.append(observer.impulse.copy())
        velocity = velocity + ((_standing(1)[0] + push[k]) / MASS + GRAVITY) * STEP
    peak = max(read, key=lambda r: math.hypot(r[0], r[1]))
    assert math.hypot(peak[0], peak[1]) == pytest.approx(0.4, rel=0.05)
    assert math.degrees(math.atan2(peak[1], peak[0])) == pytest.approx(135.0, abs=1.0)
    # out of the window once the push has passed it: the rider's new speed is no push (the
    # baseline's undershoot, the push's impulse over BASELINE_S, is left)
    assert np.linalg.norm(read[-1][:2]) < 0.1


def test_a_manoeuvre_made_by_the_contact_forces_reads_none() -> None:
    """A speed step and a sway made by the contact forces, 1 m/s^2 forward and 2 m/s^2
    sideways: the contact forces explain all of it."""
    ticks = 1500
    contact = [
        np.array(
            [MASS * (1.0 if 500 <= k < 1000 else 0.0), MASS * 2.0 * math.sin(2.0 * k * STEP), 0.0]
        )
        + _standing(1)[0]
        for k in range(ticks)
    ]
    velocity, peak = _ride(contact, [np.zeros(3)] * ticks, ImpulseObserver(MASS))
    assert velocity[0] == pytest.approx(1.0, abs=1e-6)  # it did move
    assert peak < 1e-9


def test_a_steady_force_shortfall_is_not_a_push() -> None:
    """The feet realising 0.5 N/kg less than commanded, steadily (its window alone would sum
    0.2 m/s): the baseline takes it off within a few of its time constants."""
    ticks = 5000  # 10 s
    contact = _standing(ticks)
    shortfall = [np.array([-0.5 * MASS, 0.0, 0.0])] * ticks
    observer = ImpulseObserver(MASS)
    _ride(contact, shortfall, observer)
    assert np.linalg.norm(observer.impulse[:2]) < 0.02
    # the same push on top of it still reads
    push = [np.array([0.0, 2.0 * MASS, 0.0]) if k < 100 else np.zeros(3) for k in range(200)]
    start = observer.peak
    _ride(contact[:200], [s + p for s, p in zip(shortfall, push, strict=False)], observer)
    assert observer.peak > max(start, 0.35)


def test_reset_forgets_the_window() -> None:
    observer = ImpulseObserver(MASS)
    push = [np.array([3.0 * MASS, 0.0, 0.0])] * 100
    _ride(_standing(100), push, observer)
    assert observer.impulse[0] > 0.5
    observer.reset()
    assert not observer.impulse.any()


def test_the_trigger_fires_only_beyond_its_band() -> None:
    trigger = ImpulseTrigger(BAND)
    assert trigger(np.array([0.2, 0.0, 0.0])) is None  # the library's 1 N/kg push
    assert trigger(np.array([0.2, 0.2, 5.0])) is None  # the vertical row is not read
    reason = trigger(np.array([-0.3, 0.3, 0.0]))
    assert reason is not None and "towards 135 deg" in reason
    with pytest.raises(ValueError):
        ImpulseTrigger(0.0)


def test_the_sideways_band_is_across_the_heading() -> None:
    """A narrower band across the rider: a push along world y is across a rider heading
    along x, along one heading along y."""
    trigger = ImpulseTrigger(0.3, sideways=0.15)
    push = np.array([0.0, 0.2, 0.0])
    assert trigger(push, heading=0.0) is not None
    assert trigger(push, heading=math.pi / 2) is None
    assert trigger(np.array([0.1, 0.1, 0.0])) is None  # inside the ellipse
    assert trigger(np.array([0.25, 0.1, 0.0])) is not None  # outside it


def test_the_window_holds_a_whole_push() -> None:
    """The issue's push (0.2 s) is shorter than the window: its whole impulse is summed."""
    assert WINDOW_S > 0.2
