"""The posture the MPC rider rides in on a board: its pair file's ``ride_keyframe``.

Where a board asks the MPC rider for a posture other than the one it starts in (Cassie
crouches on the Segway to reach the knee bar with her shins), that posture is the pair's
controller setting, so the pair file names it (``ride_keyframe``, a keyframe of the robot's
description); the robot's description gives its keyframes and its stance on each board, and
a pair that names none, or a robot on a board without a pair file, rides in that stance.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.pair_description import load_pair_description, pair_description_names
from ridempc.robots.robot import Robot

__all__ = ["ride_keyframe", "ride_qpos"]


def ride_keyframe(robot: Robot, board: str) -> str | None:
    """The keyframe the pair file of ``robot`` on ``board`` rides in, or None: its stance.

    Raises:
        ConfigError: The pair file is malformed.
    """
    if f"{robot.name}-{board}" not in pair_description_names():
        return None
    return load_pair_description(robot.name, board).ride_keyframe


def ride_qpos(robot: Robot, board: str) -> NDArray[np.float64]:
    """The configuration the MPC rider rides in on ``board`` [MuJoCo qpos]: the pair's
    ``ride_keyframe``, else the robot's stance on the board.

    Raises:
        ConfigError: The pair file is malformed.
    """
    name = ride_keyframe(robot, board)
    return robot.stance_qpos(board) if name is None else robot.keyframe_qpos(name)
