"""The steering roll a re-push's support holds: free on four feet, none with a foot on the
ground, only away from a swinging foot and within SWING_ROLL."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from ridempc.mpc.deck_support import SWING_ROLL, steering_bounds
from ridempc.mpc.reference import MotionReference, select_reference
from ridempc.trajopt.schedule import Contact


@pytest.fixture(scope="module")
def reference() -> MotionReference:
    return select_reference("cyberdog2", "skateboard", "repush", 0.7)


def _phase_times(
    reference: MotionReference, wanted: Callable[[tuple[Contact, ...]], bool]
) -> np.ndarray:
    """Mid-interval times of the schedule's intervals whose contacts satisfy ``wanted``."""
    dt = reference.dt
    return np.array(
        [reference.times[0] + dt * (j + 0.5) for j, c in enumerate(reference.schedule) if wanted(c)]
    )


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_the_support_bounds_the_steering_roll(reference: MotionReference, side: float) -> None:
    n = len(reference.contact_names)
    swinging = [i for i in range(n) if any(c[i] is Contact.SWING for c in reference.schedule)]
    assert len(swinging) == 1  # one pushing foot
    sides = np.ones(n)
    sides[swinging[0]] = side
    four = _phase_times(reference, lambda c: all(x is Contact.BOARD for x in c))
    ground = _phase_times(reference, lambda c: Contact.GROUND in c)
    swing = _phase_times(reference, lambda c: Contact.SWING in c)
    assert four.size and ground.size and swing.size
    low, high = steering_bounds(reference, four, sides)
    assert np.all(np.isinf(low)) and np.all(np.isinf(high))  # four feet: the stance's map
    low, high = steering_bounds(reference, ground, sides)
    np.testing.assert_array_equal(low, 0.0)  # a foot on the ground: straight
    np.testing.assert_array_equal(high, 0.0)
    low, high = steering_bounds(reference, swing, sides)
    # a foot on the left (side +1) swinging: only a positive roll (the right edge lowered,
    # the balance onto the right feet), and the other way round
    expected = (0.0, SWING_ROLL) if side > 0 else (-SWING_ROLL, 0.0)
    np.testing.assert_array_equal(low, expected[0])
    np.testing.assert_array_equal(high, expected[1])


def test_before_and_after_the_reference_the_first_and_last_phases_hold(
    reference: MotionReference,
) -> None:
    sides = np.ones(len(reference.contact_names))
    times = np.array([-1.0, reference.times[-1] + 5.0])  # a hold; a coast after the end
    low, high = steering_bounds(reference, times, sides)
    assert np.all(np.isinf(low)) and np.all(np.isinf(high))
