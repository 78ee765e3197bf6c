"""A re-push's nodes steer out of its strokes, let go over the weight shift before each and
taken up again after it (ridempc.mpc.push_steer)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.push_steer import SETTLE, WEIGHT_SHIFT, steering_nodes
from ridempc.mpc.reference import MotionReference, select_reference
from ridempc.trajopt.schedule import Contact


def _strokes(reference: MotionReference) -> list[tuple[float, float]]:
    strokes, start = [], 0.0
    for phase in reference.phases:
        if Contact.GROUND in phase.contacts:
            strokes.append((start, start + phase.duration))
        start += phase.duration
    return strokes


def test_a_stroke_goes_straight_and_the_steering_fades_out_before_and_in_after() -> None:
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    strokes = _strokes(reference)
    assert len(strokes) >= 2
    (down, up), (next_down, _) = strokes[0], strokes[1]
    assert next_down - up > WEIGHT_SHIFT + SETTLE  # a swing long enough to steer in
    dt = 0.01
    t_ref = down - 0.5  # half a second before the first stroke
    times = t_ref + dt * np.arange(round((next_down - t_ref) / dt))
    factor = steering_nodes(reference, t_ref, len(times), dt)
    assert np.all(factor[times < down - WEIGHT_SHIFT - 1e-9] == 1.0)  # the swing before steers
    assert np.all(factor[(times >= down) & (times < up)] == 0.0)  # the stroke goes straight
    shifting = (times > down - WEIGHT_SHIFT) & (times < down)
    np.testing.assert_allclose(factor[shifting], (down - times[shifting]) / WEIGHT_SHIFT)
    settling = (times > up) & (times < up + SETTLE)
    np.testing.assert_allclose(factor[settling], (times[settling] - up) / SETTLE)
    swing = (times >= up + SETTLE + 1e-9) & (times < next_down - WEIGHT_SHIFT - 1e-9)
    assert swing.any() and np.all(factor[swing] == 1.0)
    assert np.all(np.abs(np.diff(factor)) <= dt / min(WEIGHT_SHIFT, SETTLE) + 1e-12)


def test_an_entry_past_its_strokes_steers_throughout() -> None:
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    after = _strokes(reference)[-1][1] + SETTLE
    assert steering_nodes(reference, after, 13, 1.0 / 30.0) == pytest.approx(np.ones(13))
