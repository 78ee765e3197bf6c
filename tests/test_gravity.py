"""The package's one value of g is the simulator's: every robot on every board falls by it."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.gravity import GRAVITY, GRAVITY_WORLD
from ridempc.pair_description import pair_description_names
from ridempc.robots.robot import load_robot, robot_names
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene

PAIRS = [(robot, None) for robot in robot_names()] + [
    tuple(name.split("-", 1)) for name in pair_description_names()
]


@pytest.mark.parametrize(("robot", "board"), PAIRS)
def test_every_scene_falls_by_the_package_gravity(robot: str, board: str | None) -> None:
    scene = build_scene(
        load_robot(robot), DEFAULT_PHYSICS_HZ, load_board(board) if board is not None else None
    )
    np.testing.assert_array_equal(scene.model.opt.gravity, GRAVITY_WORLD)


def test_the_world_vector_is_the_magnitude_down_and_read_only() -> None:
    assert GRAVITY_WORLD[2] == -GRAVITY and not GRAVITY_WORLD[:2].any()
    with pytest.raises(ValueError):
        GRAVITY_WORLD[2] = 0.0
