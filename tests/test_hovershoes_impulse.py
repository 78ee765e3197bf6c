"""Cassie on the Hovershoes: the ``[stages.impulse]`` band across the rider from its physics.

Across the shoes' travel the rider stands on two wheels' treads, one under each foot, and
tips over the outer one once the capture point of the pushed rider passes that foot: a
push's velocity change :math:`\\Delta v` puts the capture point :math:`\\Delta v / \\omega`
further out, :math:`\\omega = \\sqrt{g / H}` with :math:`H` the centre of mass over the
ground, so the largest push the stance holds without a step is
:math:`(w/2) \\sqrt{g / H}` [m/s], :math:`w` the feet's spacing.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from ridempc.boards.registry import load_board
from ridempc.mpc.impulse import ImpulseTrigger
from ridempc.pair_description import load_pair_description
from ridempc.robots.robot import load_robot

GRAVITY = 9.81  # [m/s^2]
ROUNDING = 0.01  # [m/s] the pair file gives the band to two figures
LIBRARY_PUSH = 0.2  # [m/s] the library's push: 1 N/kg for 0.2 s


def _reach_across() -> float:
    """The capture point's reach to a foot across the shoes [m/s], from Cassie's stance
    on the Hovershoes and the shoes' deck height."""
    robot = load_robot("cassie")
    data = mujoco.MjData(robot.mj_model)
    data.qpos[:] = robot.stance_qpos("hovershoes")
    mujoco.mj_forward(robot.mj_model, data)
    feet = np.array([data.site(name).xpos for name in robot.params.contact_sites])
    half_spacing = float(np.abs(feet[:, 1] - feet[:, 1].mean()).mean())
    board = load_board("hovershoes")
    assert board is not None
    over_ground = float(data.subtree_com[0][2] - feet[:, 2].mean() + board.params.platform_height)
    return half_spacing * math.sqrt(GRAVITY / over_ground)


def test_the_band_across_is_the_capture_points_reach_to_a_foot() -> None:
    stage = load_pair_description("cassie", "hovershoes").stages.impulse
    assert stage is not None and stage.sideways is not None
    assert stage.sideways == pytest.approx(_reach_across(), abs=ROUNDING)


def test_a_sideways_push_inside_the_stance_stays_on_the_mpc() -> None:
    """A push across that leaves the capture point between the feet is not handed over;
    the same push along the heading, beyond the feet's length, is."""
    stage = load_pair_description("cassie", "hovershoes").stages.impulse
    assert stage is not None
    trigger = ImpulseTrigger(stage.band, stage.sideways)
    inside = 0.9 * _reach_across()  # [m/s]
    assert trigger(np.array([0.0, inside, 0.0])) is None
    assert trigger(np.array([0.0, -inside, 0.0])) is None
    assert trigger(np.array([inside, 0.0, 0.0])) is not None
    assert trigger(np.array([0.0, 1.1 * _reach_across(), 0.0])) is not None
    assert trigger(np.array([LIBRARY_PUSH, 0.0, 0.0])) is None  # the library's own push
