"""The MPC rider's wave pattern: each platform's reference line moved out sideways."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.foot_spread import spread_lines

# two platforms' (x, y, heading) in a state of 7: a spare column first
COLUMNS = ((1, 2, 3), (4, 5, 6))


def _pair(heading: float) -> np.ndarray:
    """Three nodes of two platforms 0.42 m apart across ``heading``."""
    normal = np.array([-np.sin(heading), np.cos(heading)])
    states = np.zeros((3, 7))
    for node in range(3):
        ahead = 0.1 * node * np.array([np.cos(heading), np.sin(heading)])
        states[node, [1, 2]] = ahead + 0.21 * normal
        states[node, [4, 5]] = ahead - 0.21 * normal
        states[node, [3, 6]] = heading
    return states


@pytest.mark.parametrize("heading", [0.0, 0.7, -2.5])
def test_the_platforms_move_apart_by_twice_the_offset_across_their_heading(
    heading: float,
) -> None:
    states = _pair(heading)
    spread = spread_lines(states, COLUMNS, 0.05)
    gap = np.linalg.norm(spread[:, [1, 2]] - spread[:, [4, 5]], axis=1)
    assert gap == pytest.approx(0.52)
    middle = 0.5 * (spread[:, [1, 2]] + spread[:, [4, 5]])
    assert middle == pytest.approx(0.5 * (states[:, [1, 2]] + states[:, [4, 5]]))
    assert spread[:, [0, 3, 6]] == pytest.approx(states[:, [0, 3, 6]])  # nothing else moves


def test_no_offset_changes_nothing() -> None:
    states = _pair(0.3)
    assert np.array_equal(spread_lines(states, COLUMNS, 0.0), states)
