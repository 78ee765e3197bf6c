"""Any robot on any board: feet on the platform(s), a settled start, no launch."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from ridempc.boards import board_names, load_board
from ridempc.controllers import make_controller
from ridempc.errors import ConfigError
from ridempc.robots import load_robot, robot_names
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import FOOT_CLEARANCE, build_scene
from ridempc.sim.simulation import Simulation
from tests.helpers import scenario

BOARDS = [b for b in board_names() if b != "none"]
PAIRS = [(r, b) for r in robot_names() for b in BOARDS]
# A quadruped's four feet fit neither on two foot-sized shoes nor between a Segway's wheels.
MISFITS = {
    (r, b)
    for r in robot_names()
    if load_robot(r).params.kind == "quadruped"
    for b in ("hovershoes", "segway")
}
MISSION = {"hovershoes": "cassie", "segway": "cassie", "skateboard": "cyberdog2"}
SINK = 0.003  # [m] deepest a standing foot may press into a board


@pytest.mark.parametrize(("robot_name", "board_name"), PAIRS)
def test_rider_starts_settled_on_the_board(robot_name: str, board_name: str) -> None:
    robot, board = load_robot(robot_name), load_board(board_name)
    if (robot_name, board_name) in MISFITS:
        with pytest.raises(ConfigError, match="platforms|does not fit"):
            build_scene(robot, DEFAULT_PHYSICS_HZ, board=board)
        return
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, board=board)
    model, data = scene.model, scene.data
    assert all(data.contact[i].dist > -1e-4 for i in range(data.ncon)), "interpenetration"
    feet = scene.foot_bodies
    # the feet start just above the platform, not on the floor
    lowest = min(data.xpos[b, 2] for b in feet)
    assert lowest > scene.support_height - 0.05
    assert scene.support_height > 0.05
    result = Simulation(scene, make_controller("stand", robot), scenario(0.3)).run()
    assert result.status == "ok", result.fall_reason
    speed = np.linalg.norm(result.log["base_velocity"], axis=1)
    assert speed.max() < 0.5, "launched"
    # the feet rest on the board: a contact between each foot and a board geom
    board_geoms = {g for g in range(model.ngeom) if model.geom_bodyid[g] in scene.board_bodies}
    touching = set()
    sinks: list[float] = []
    for i in range(data.ncon):
        g1, g2 = data.contact[i].geom
        for foot_geom, other in ((g1, g2), (g2, g1)):
            if model.geom_bodyid[foot_geom] in feet and other in board_geoms:
                touching.add(int(model.geom_bodyid[foot_geom]))
                sinks.append(-data.contact[i].dist)
    assert touching == set(feet)
    # hard soles on a hard deck: a foot sinks a millimetre or two, not a centimetre (the
    # estimator reads the deck's roll off the feet; 9 mm on the dog's 0.17 m stance read
    # 0.116 rad for 0.077)
    assert max(sinks) < SINK, f"a foot sinks {max(sinks) * 1e3:.1f} mm into the board"
    assert FOOT_CLEARANCE < 0.01


@pytest.mark.parametrize("board_name", BOARDS)
def test_feet_can_start_off_centre(board_name: str) -> None:
    robot, board = load_robot(MISSION[board_name]), load_board(board_name)
    centred = build_scene(robot, DEFAULT_PHYSICS_HZ, board=board)
    offset = build_scene(robot, DEFAULT_PHYSICS_HZ, board=board, foot_offset=(0.03, 0.01))
    site = mujoco.mj_name2id(
        centred.model, mujoco.mjtObj.mjOBJ_SITE, "board/" + board.params.platform_sites[0]
    )
    relative = [
        s.data.xpos[s.base_body, :2] - s.data.site_xpos[site, :2] for s in (centred, offset)
    ]
    assert np.allclose(relative[1] - relative[0], (0.03, 0.01), atol=1e-9)


def test_a_push_off_may_put_a_foot_down_but_not_every_foot() -> None:
    """On a board a foot on the ground is a fall; in a push-off (``feet_on_ground``) one foot
    may stand there, but the dog standing on the floor beside its deck has stepped off."""
    from ridempc.sim.falls import FallDetector

    scene = build_scene(load_robot("cyberdog2"), DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
    model, data = scene.model, scene.data
    scene.reset()
    mujoco.mj_forward(model, data)
    assert FallDetector(scene, feet_on_ground=True).check(model, data) is None  # on the deck
    data.qpos[0] += 1.0  # beside the deck
    data.qpos[2] -= scene.support_height + 0.002  # on the floor, pressed 2 mm into it
    mujoco.mj_forward(model, data)
    assert "stepped off" in (FallDetector(scene, feet_on_ground=True).check(model, data) or "")
    assert "touched the ground" in (FallDetector(scene).check(model, data) or "")


def test_segway_start_has_the_load_over_the_axle() -> None:
    """A self-balancing board at rest holds still only with the rider and board's centre of
    mass over its wheels' axle; the Segway stance keyframe is leaned so that the start has it."""
    scene = build_scene(load_robot("cassie"), DEFAULT_PHYSICS_HZ, board=load_board("segway"))
    model, data = scene.model, scene.data
    bodies = sorted(scene.rider_bodies | scene.board_bodies)
    com_x = model.body_mass[bodies] @ data.xipos[bodies, 0] / model.body_mass[bodies].sum()
    axle_x = np.mean([data.xpos[b, 0] for b in scene.board_ground_bodies])
    assert abs(com_x - axle_x) < 0.002
