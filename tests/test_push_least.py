"""The least speed a re-push's stroke lands on, from its impulse and the masses
(ridempc.mpc.push_least)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.push_least import first_stroke, least_start, repush_start, stroke_speed
from ridempc.mpc.push_speed import ROLLING_DECELERATION
from ridempc.mpc.reference import select_reference
from ridempc.trajopt.schedule import Contact

ROBOT, BOARD = "cyberdog2", "skateboard"


def _reference():  # type: ignore[no-untyped-def]
    return select_reference(ROBOT, BOARD, "repush", 0.7)


def test_the_stroke_speed_is_its_impulse_over_rider_and_board() -> None:
    """:math:`v_J = J/(m + m_B)`: the ground foot's force along the board summed over the
    stroke's steps, by hand; twice the masses halve it."""
    reference = _reference()
    down, up = first_stroke(reference) or (0.0, 0.0)
    assert 0.0 < down < up
    impulse = 0.0
    for k, t in enumerate(reference.times[:-1]):
        if down - 1e-9 <= t < up - 1e-9:
            for i, contact in enumerate(reference.schedule[k]):
                if contact is Contact.GROUND:
                    impulse += reference.inputs[k, reference.force_index[i][0]] * reference.dt
    assert impulse > 0.0  # a stroke pushes the rider forward
    assert stroke_speed(reference, 8.9, 3.2) == pytest.approx(impulse / 12.1)
    assert stroke_speed(reference, 17.8, 6.4) == pytest.approx(impulse / 24.2)


def test_the_start_adds_the_entrys_weight_shift_and_the_rolling_loss() -> None:
    reference = _reference()
    column = list(reference.state_names).index("board_v")
    down = (first_stroke(reference) or (0.0, 0.0))[0]
    speeds = reference.states[:, column]
    lost = max(0.0, speeds[0] - np.interp(down, reference.times, speeds))
    expected = stroke_speed(reference, 8.9, 3.2) + lost + ROLLING_DECELERATION * down
    assert least_start(reference, 8.9, 3.2, column) == pytest.approx(expected)
    assert least_start(reference, 8.9, 3.2, column, deceleration=0.0) == pytest.approx(
        expected - ROLLING_DECELERATION * down
    )


def test_the_pairs_least_start_lies_between_the_stroke_speed_and_the_command() -> None:
    """For the CyberDog2 at 0.7 m/s: above the re-push band's start (0.5 m/s), below the
    command, a heavier rider's (the Go1's) stroke giving less speed per kilogram."""
    column = list(_reference().state_names).index("board_v")
    dog = repush_start(ROBOT, BOARD, 0.7, column)
    assert 0.5 < dog < 0.7
    assert repush_start("go1", BOARD, 0.7, column) < dog
