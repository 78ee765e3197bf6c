"""A bounce's way down told from support giving way (ridempc/mpc/bounce.py), and the drop's
watch that reads it (ridempc/mpc/stages/triggers.py)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any, cast

import numpy as np

from ridempc.mpc.bounce import BounceRise
from ridempc.mpc.drop import ARM_TICKS, DROP_LOAD, DROP_TICKS, DropDetector
from ridempc.mpc.stages.triggers import DropWatch

DT = 0.002  # [s] a control tick at 500 Hz
G = 9.81  # [m/s^2]


def test_a_bounce_counts_as_rising_until_she_sinks_faster_than_she_rose() -> None:
    bounce = BounceRise()
    assert bounce.update(0.1) == 0.1 and bounce.update(0.19) == 0.19
    assert bounce.update(-0.05) > 0.0  # past the top: on the bounce's way down
    assert bounce.update(-0.18) > 0.0
    assert bounce.update(-0.2) == -0.2  # past the speed she rose at: sinking
    assert bounce.rise == 0.0 and bounce.update(-0.01) == -0.01


def test_a_new_rise_replaces_the_last() -> None:
    bounce = BounceRise()
    bounce.update(0.3)
    bounce.update(-0.1)
    bounce.update(0.02)  # a small rise after the big one's top: the big one is spent
    assert abs(bounce.update(-0.01) - 0.01) < 1e-12
    assert bounce.update(-0.03) == -0.03
    bounce.reset()
    assert bounce.update(-0.01) == -0.01


def _tick(load: float, vz: float) -> Any:
    estimate = SimpleNamespace(
        base_velocity=np.array([0.0, 0.0, vz]), foot_velocity=np.zeros((2, 3))
    )
    return cast(Any, SimpleNamespace(estimate=estimate, loads=np.full(2, load)))


def _stood(watch: DropWatch) -> None:
    for _ in range(ARM_TICKS):
        watch.observe(_tick(1.0, 0.0))
        assert not watch.dropping


def test_the_top_of_a_bounce_after_a_takeover_is_no_drop() -> None:
    """Pressed up at 0.19 m/s and falling back at half a g with every foot unloaded (a
    +29 % payload's bounce): no drop while she sinks slower than she rose."""
    watch = DropWatch(DropDetector())
    _stood(watch)
    vz = 0.19
    while vz > 0.0:  # the rise, decelerating at half a g, the loads going
        watch.observe(_tick(1.0 - 0.5 * (0.19 - vz) / 0.19, vz))
        vz -= 0.5 * G * DT
    told = []
    while vz > -0.18:  # the way down, every foot below the drop's load
        watch.observe(_tick(0.5 * DROP_LOAD, vz))
        told.append(watch.dropping)
        vz -= 0.5 * G * DT
    assert len(told) > 10 and not any(told)


def test_a_platform_falling_away_under_a_still_rider_is_a_drop_at_once() -> None:
    watch = DropWatch(DropDetector())
    _stood(watch)
    told = []
    for k in range(DROP_TICKS + 3):  # unloaded, falling freely from rest
        watch.observe(_tick(0.1, -G * DT * (k + 1)))
        told.append(watch.dropping)
    assert told.index(True) == DROP_TICKS - 1
