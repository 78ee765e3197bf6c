"""Each Hovershoe steered back onto its line (``ridempc.mpc.guidance``)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.guidance import MAX_TURN, TAU, steer_onto_lines

# two platforms' (x, y, heading, speed) columns in a state of 8
COLUMNS = ((0, 1, 2, 3), (4, 5, 6, 7))


def _reference(heading: float, speed: float, nodes: int = 4) -> np.ndarray:
    states = np.zeros((nodes, 8))
    states[:, [2, 6]] = heading
    states[:, [3, 7]] = speed
    states[:, 5] = -0.4  # the right shoe 0.4 m to the right of the left one (heading 0)
    return states


def test_a_shoe_off_its_line_is_turned_back_towards_it() -> None:
    """The right shoe 5 cm too far left (feet too close) at 0.5 m/s is turned right by
    e / (v tau) over the whole horizon; the left shoe, on its line, is left alone."""
    states = _reference(0.0, 0.5)
    x0 = states[0].copy()
    x0[5] += 0.05
    out = steer_onto_lines(states, x0, COLUMNS)
    np.testing.assert_allclose(out[:, 6], -0.05 / (0.5 * TAU))
    np.testing.assert_array_equal(out[:, 2], states[:, 2])
    np.testing.assert_array_equal(np.delete(out, [6], axis=1), np.delete(states, [6], axis=1))


def test_the_error_is_taken_across_the_reference_heading_and_the_turn_is_bounded() -> None:
    """Heading pi/2 (riding along +y): an error along x is sideways, one along y is not;
    a large error turns by at most MAX_TURN; backwards the turn changes sign."""
    states = _reference(np.pi / 2, 0.5)
    x0 = states[0].copy()
    x0[0] += 0.01  # 1 cm to the right of the left shoe's line (its left is -x)
    x0[1] += 0.3  # 30 cm ahead: along the line, no turn for it
    out = steer_onto_lines(states, x0, COLUMNS)
    assert out[0, 2] - np.pi / 2 == pytest.approx(0.01 / (0.5 * TAU))
    x0[0] += 1.0
    assert steer_onto_lines(states, x0, COLUMNS)[0, 2] - np.pi / 2 == pytest.approx(MAX_TURN)
    backwards = _reference(np.pi / 2, -0.5)
    x0 = backwards[0].copy()
    x0[0] += 0.01
    turned = steer_onto_lines(backwards, x0, COLUMNS)[0, 2] - np.pi / 2
    assert turned == pytest.approx(-0.01 / (0.5 * TAU))


def test_a_shoe_at_rest_is_not_turned() -> None:
    states = _reference(0.0, 0.1)
    x0 = states[0].copy()
    x0[5] += 0.1
    np.testing.assert_array_equal(steer_onto_lines(states, x0, COLUMNS), states)
