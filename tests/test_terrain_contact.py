"""The Hovershoes' tread on the terrain: an edge carries the wheel along its radius."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from ridempc.boards import load_board
from ridempc.scenarios import load_scenario_file
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.terrain import lay_out

STEP = (
    'name = "t"\nduration = 2.0\n'
    '[[terrain]]\nkind = "step"\nat = 1.0\nheight_radii = 1.71\ndirection = "down"\n'
)


def _scene(tmp_path: Path):
    path = tmp_path / "s.toml"
    path.write_text(STEP)
    board = load_board("hovershoes")
    layout = lay_out(load_scenario_file(path).terrain, board.params.wheel_radius, board.name)
    return build_scene(None, DEFAULT_PHYSICS_HZ, board=board, dead_weight=32.8, terrain=layout)


def _wheel_contacts(model: mujoco.MjModel, data: mujoco.MjData) -> list[tuple[str, np.ndarray]]:
    """(geom name on the board, contact normal pointing into the wheel) of the left wheel."""
    out = []
    for con in data.contact[: data.ncon]:
        names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "" for g in con.geom]
        if not any("left_t" in n for n in names):
            continue
        wheel_first = "left_t" in names[0]
        normal = np.array(con.frame[:3]) * (-1.0 if wheel_first else 1.0)
        out.append((names[0] if wheel_first else names[1], normal))
    return out


def test_a_wheel_over_a_step_edge_is_pushed_along_its_radius(tmp_path: Path) -> None:
    scene = _scene(tmp_path)
    model, data = scene.model, scene.data
    root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "board/left_shoe_root")
    address = model.jnt_qposadr[root]
    radius = load_board("hovershoes").params.wheel_radius
    for angle in (0.1, 0.3, 0.6):  # the axle this far round the edge [rad]
        reach = radius - 0.0005  # half a millimetre into the edge
        data.qpos[address : address + 3] = [
            1.0 + reach * math.sin(angle),
            data.qpos[address + 1],
            reach * math.cos(angle),
        ]
        data.qpos[address + 3 : address + 7] = [1.0, 0.0, 0.0, 0.0]
        mujoco.mj_forward(model, data)
        contacts = _wheel_contacts(model, data)
        assert contacts, angle
        for name, normal in contacts:
            assert name.endswith("left_tread"), name  # the cylinder leaves the terrain to it
            expected = np.array([math.sin(angle), 0.0, math.cos(angle)])
            assert normal @ expected > 0.99, (angle, normal)


def test_on_flat_ground_the_tread_touches_nothing(tmp_path: Path) -> None:
    board = load_board("hovershoes")
    scene = build_scene(None, DEFAULT_PHYSICS_HZ, board=board, dead_weight=32.8)
    mujoco.mj_forward(scene.model, scene.data)
    names = [name for name, _ in _wheel_contacts(scene.model, scene.data)]
    assert names and all(n.endswith("left_tyre") for n in names)
