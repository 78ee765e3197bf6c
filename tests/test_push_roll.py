"""A re-push's steering roll: the turn its strokes lose made up in its swings, held within the
stance's roll and laid in at its rate (ridempc.mpc.push_roll)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.boards.skateboard.steering import STANCE_ROLL
from ridempc.mpc.push_roll import (
    ROLL_RATE,
    RollRate,
    repush_steering,
    steering_share,
    turn_makeup,
)
from ridempc.mpc.push_steer import SETTLE, steering_nodes
from ridempc.mpc.reference import select_reference


def test_the_entrys_mean_turn_is_the_commanded_one() -> None:
    """Over the whole entry the made-up steering averages 1: the commanded turn, all of it."""
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    share = steering_share(reference)
    assert 0.3 < share < 1.0  # its strokes and their ramps go straight
    length = float(sum(phase.duration for phase in reference.phases))
    dt = 0.01
    nodes = round(length / dt) + 1
    made_up = repush_steering(reference, 0.0, nodes, dt)
    assert np.mean(made_up) == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(made_up, steering_nodes(reference, 0.0, nodes, dt) / share)


def test_an_entry_without_strokes_is_not_made_up() -> None:
    reference = select_reference("cyberdog2", "skateboard", "accelerate", 0.7)
    assert turn_makeup(np.array([0.0, 0.5, 1.0]), 1.0) == pytest.approx([0.0, 0.5, 1.0])
    assert turn_makeup(np.ones(3), 0.0) == pytest.approx(np.zeros(3))
    assert steering_share(reference) < 1.0  # a push-off's strokes go straight too


def test_the_rate_is_the_stances_roll_over_the_settle() -> None:
    assert ROLL_RATE == pytest.approx(STANCE_ROLL / SETTLE)


def test_the_roll_is_held_within_the_stance_and_laid_in_at_its_rate() -> None:
    """A step to the far side of the stance's roll: clipped to 0.12 rad and ramped from the
    last tick's first node, at most ``rate * dt`` a node and ``rate * elapsed`` a tick."""
    rate = RollRate(rate=0.6, limit=0.12)
    held = rate.follow(np.array([0.01, 0.01, 0.01]), now=1.0)
    np.testing.assert_array_equal(held, [0.01, 0.01, 0.01])  # balancing: as the stance held it
    out = rate(np.full(6, -0.3), now=1.1, dt=0.05)
    np.testing.assert_allclose(out, [-0.05, -0.08, -0.11, -0.12, -0.12, -0.12])
    again = rate(np.full(3, -0.3), now=1.1, dt=0.05)  # the same instant: no further
    assert again[0] == pytest.approx(-0.05)


def test_a_first_roll_is_clipped_only_and_a_small_one_passes() -> None:
    rate = RollRate()
    np.testing.assert_allclose(rate(np.array([0.5, 0.5]), 0.0, 0.05), [STANCE_ROLL] * 2)
    fresh = RollRate()
    small = np.array([0.0, 0.01, 0.02])
    np.testing.assert_array_equal(fresh(small, 0.0, 0.05), small)
