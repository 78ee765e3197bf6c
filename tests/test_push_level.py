"""A re-push's steering roll eased out before each touchdown (:mod:`ridempc.mpc.push_level`)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.push_level import EASE, eased_roll, touchdown_ease
from ridempc.mpc.reference import select_reference
from ridempc.trajopt.schedule import Contact


def _ground_spans(reference) -> list[tuple[float, float]]:  # type: ignore[no-untyped-def]
    spans, start = [], reference.times[0]
    for phase in reference.phases:
        if Contact.GROUND in phase.contacts:
            spans.append((start, start + phase.duration))
        start += phase.duration
    return spans


def test_the_deck_is_level_on_the_ground_and_steers_again_before_and_after() -> None:
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    spans = _ground_spans(reference)
    assert len(spans) == 2
    (land, lift), (land2, lift2) = spans
    times = np.array([0.0, land - EASE - 0.05, land - EASE / 2, land + 0.05, lift - 0.05])
    share = touchdown_ease(reference, times)
    np.testing.assert_allclose(share, [1.0, 1.0, 0.5, 0.0, 0.0], atol=1e-6)
    after = touchdown_ease(reference, np.array([lift2 + 0.05, reference.times[-1] + 1.0]))
    np.testing.assert_allclose(after, [1.0, 1.0])  # no touchdown ahead: steered again
    between = touchdown_ease(reference, np.array([lift + 0.05]))
    assert between[0] == pytest.approx(min(1.0, (land2 - lift - 0.05) / EASE))


def test_only_the_roll_that_raises_the_pushing_foot_is_eased() -> None:
    steering = np.array([0.1, -0.1, 0.05])  # positive: the right edge down
    share = np.array([0.5, 0.5, 0.0])
    # a right foot (-1) rises with the left edge down: negative rolls eased
    np.testing.assert_allclose(eased_roll(steering, share, -1.0), [0.1, -0.05, 0.05])
    np.testing.assert_allclose(eased_roll(steering, share, 1.0), [0.05, -0.1, 0.0])
    np.testing.assert_allclose(eased_roll(steering, share, None), [0.05, -0.05, 0.0])
