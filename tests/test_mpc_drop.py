"""A drop under the rider: every foot's load gone at once (ridempc/mpc/drop.py)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.drop import ARM_TICKS, DROP_LOAD, DROP_TICKS, SINK_SPEED, DropDetector
from ridempc.pair_description import load_pair_description

SINKING = -0.1  # [m/s] the rider coming down with her support (a step's first 0.1 s)
STILL = 0.0  # [m/s] the feet's platforms on the ground


def _stood(detector: DropDetector) -> None:
    for _ in range(ARM_TICKS):
        assert not detector.update(np.array([1.0, 1.0]), SINKING, STILL)


def test_every_foot_unloaded_for_the_ticks_is_a_drop() -> None:
    detector = DropDetector()
    _stood(detector)
    low = np.array([0.5 * DROP_LOAD, 0.9 * DROP_LOAD])
    told = [detector.update(low, SINKING, STILL) for _ in range(DROP_TICKS + 2)]
    assert told == [False] * (DROP_TICKS - 1) + [True] * 3


def test_one_foot_lifted_is_no_drop() -> None:
    """A foot lifted on purpose (a skateboard's push) leaves another loaded."""
    detector = DropDetector()
    _stood(detector)
    assert not any(detector.update(np.array([0.0, 1.0]), SINKING, STILL) for _ in range(100))


def test_a_single_low_tick_is_no_drop_and_loads_back_end_it() -> None:
    detector = DropDetector()
    _stood(detector)
    low, loaded = np.zeros(2), np.ones(2)
    assert not detector.update(low, SINKING, STILL)
    assert not detector.update(loaded, SINKING, STILL)
    assert not detector.update(low, SINKING, STILL)
    for _ in range(DROP_TICKS):
        detector.update(low, SINKING, STILL)
    assert detector.update(low, SINKING, STILL)
    assert not detector.update(loaded, SINKING, STILL)


def test_a_rider_not_yet_standing_drops_nothing() -> None:
    """The ride's first ticks, before every foot has carried its share, are no drop."""
    detector = DropDetector()
    assert not detector.update(np.ones(2), SINKING, STILL)  # the detector's placeholder loads
    assert not any(detector.update(np.zeros(2), SINKING, STILL) for _ in range(100))
    detector.reset()
    _stood(detector)
    assert [detector.update(np.zeros(2), SINKING, STILL) for _ in range(DROP_TICKS)][-1]


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError, match="threshold"):
        DropDetector(threshold=1.5)
    with pytest.raises(ValueError, match="ticks"):
        DropDetector(ticks=0)


def test_the_hovershoes_pair_uses_the_drop_and_the_others_do_not() -> None:
    assert load_pair_description("cassie", "hovershoes").stages.drop is not None
    for robot, board in (("cassie", "segway"), ("cyberdog2", "skateboard")):
        assert load_pair_description(robot, board).stages.drop is None


def test_a_lighter_rider_s_sway_is_no_drop_but_her_fall_is() -> None:
    """Loads are fractions of the modelled rider's share: a rider 30 % lighter stands at
    0.7, and a sway that takes both feet to 0.55 of it is no drop; both feet at 0.3 is."""
    detector = DropDetector()
    standing = np.full(2, 0.7)
    for _ in range(3000):  # [ticks] 6 s standing: the mean learns her weight
        assert not detector.update(standing, SINKING, STILL)
    assert not any(detector.update(np.full(2, 0.55), SINKING, STILL) for _ in range(20))
    assert not detector.update(standing, SINKING, STILL)
    assert [detector.update(np.full(2, 0.3), SINKING, STILL) for _ in range(2)] == [False, True]


def test_a_bounce_s_top_is_no_drop() -> None:
    """Unloaded while rising, the rider's legs are letting her decelerate, as at the top of
    a bounce after the MPC's takeover (hard seed 53 v0024: both feet at 0.55 rising at
    0.1 m/s); unloaded while sinking, her support is giving way."""
    detector = DropDetector()
    _stood(detector)
    low = np.full(2, 0.5 * DROP_LOAD)
    assert not any(detector.update(low, 0.1, STILL) for _ in range(20))
    assert [detector.update(low, SINKING, STILL) for _ in range(DROP_TICKS)][-1]


def test_every_foot_sinking_fast_is_a_drop_before_the_loads_go() -> None:
    """Held on by the plan's forces, the feet follow their falling platforms down while
    still loaded; one foot sinking (a platform pitching) is no drop."""
    detector = DropDetector()
    _stood(detector)
    loaded = np.ones(2)
    fast = -1.5 * SINK_SPEED
    assert not any(detector.update(loaded, STILL, 0.5 * fast) for _ in range(20))
    assert [detector.update(loaded, STILL, fast) for _ in range(DROP_TICKS)][-1]
