"""The Go1-class quadruped (``robots/go1/``): its public figures, and a stand under a joint PD.

The figures are Unitree's, as the ``unitree_go1`` model of MuJoCo Menagerie and Unitree's URDF
give them (``robots/go1/README.md``). The stand is raw MuJoCo on a floor, each motor holding the
``stand`` keyframe with its ``robot.toml`` gains, so it checks the description alone.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from ridempc.mjcf import STIFF_CONTACT
from ridempc.robots import load_robot
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ

LEGS = ("FL", "FR", "RL", "RR")
STAND_TIME = 3.0  # [s] long enough for the trunk to settle (0.5 s) and show any drift


@pytest.fixture(scope="module")
def go1():
    return load_robot("go1")


def _position(model: mujoco.MjModel, data: mujoco.MjData, kind: mujoco.mjtObj, name: str):
    index = mujoco.mj_name2id(model, kind, name)
    assert index >= 0, name
    if kind == mujoco.mjtObj.mjOBJ_SITE:
        return data.site_xpos[index].copy()
    return data.xanchor[index].copy()


def test_go1_has_its_public_figures(go1) -> None:
    """About 12.7 kg; 0.213 m thigh and calf; 23.7 / 35.55 N m; 30.1 / 20.06 rad/s; 0.02 m feet."""
    model = go1.mj_model
    assert go1.params.kind == "quadruped"
    assert go1.mass == pytest.approx(12.743, abs=0.001)  # the Menagerie model's links
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(go1.params.stand_keyframe).id)
    mujoco.mj_forward(model, data)
    joint = mujoco.mjtObj.mjOBJ_JOINT
    for leg in LEGS:
        hip = _position(model, data, joint, f"{leg}_hip")
        knee = _position(model, data, joint, f"{leg}_knee")
        foot = _position(model, data, mujoco.mjtObj.mjOBJ_SITE, f"{leg}_contact")
        assert np.linalg.norm(knee - hip) == pytest.approx(0.213)
        assert np.linalg.norm(foot - knee) == pytest.approx(0.213)
        abad = _position(model, data, joint, f"{leg}_abad")
        assert np.abs(abad[:2] - data.qpos[:2]) == pytest.approx([0.1881, 0.04675])
    limits = {m.name.split("_")[1]: (m.torque_limit, m.speed_limit) for m in go1.motors}
    assert limits["abad"] == pytest.approx((23.7, 30.1))
    assert limits["hip"] == pytest.approx((23.7, 30.1))
    assert limits["knee"] == pytest.approx((35.55, 20.06))
    feet = [g for g in range(model.ngeom) if model.geom_bodyid[g] in _foot_bodies(go1, model)]
    assert feet and all(model.geom_size[g, 0] == pytest.approx(0.02) for g in feet)


def _foot_bodies(robot, model: mujoco.MjModel) -> set[int]:
    return {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in robot.params.foot_bodies}


def _on_a_floor(robot) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The description over a hard floor, its ``stand`` keyframe lowered to 1 mm above it."""
    spec = robot.spec()
    spec.option.timestep = 1.0 / DEFAULT_PHYSICS_HZ
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    floor = spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5.0, 5.0, 0.1])
    floor.contype, floor.conaffinity = 1, 3
    floor.solref, floor.solimp = STIFF_CONTACT["solref"], STIFF_CONTACT["solimp"]
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(robot.params.stand_keyframe).id)
    mujoco.mj_forward(model, data)
    lowest = min(
        data.geom_xpos[g, 2] - model.geom_size[g, 0]
        for g in range(model.ngeom)
        if model.geom_bodyid[g] in _foot_bodies(robot, model)
    )
    data.qpos[2] -= lowest - 0.001
    mujoco.mj_forward(model, data)
    return model, data


def test_go1_stands_under_a_joint_pd(go1) -> None:
    """kp (q_stand - q) - kd qdot at every physics step holds the trunk up and level."""
    model, data = _on_a_floor(go1)
    target = data.qpos[7:].copy()
    kp = np.array([m.kp for m in go1.motors])
    kd = np.array([m.kd for m in go1.motors])
    gear = model.actuator_gear[:, 0]
    low, high = model.actuator_ctrlrange.T
    trunk = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, go1.params.base_body)
    start = data.qpos[:3].copy()
    sites = [model.site(s).id for s in go1.params.contact_sites]
    settled = round(DEFAULT_PHYSICS_HZ)  # [steps] 1 s; the trunk settles within 0.5 s
    feet = data.site_xpos[sites, :2].copy()
    heights, uprights = [], []
    for step in range(round(STAND_TIME * DEFAULT_PHYSICS_HZ)):
        if step == settled:
            feet = data.site_xpos[sites, :2].copy()
        torque = kp * (target - data.qpos[7:]) - kd * data.qvel[6:]
        data.ctrl[:] = np.clip(torque / gear, low, high)
        mujoco.mj_step(model, data)
        heights.append(data.qpos[2])
        uprights.append(data.xmat[trunk, 8])  # world z of the trunk's z axis
    heights_after = np.array(heights[settled:])
    assert start[2] - heights[-1] < 0.02  # joint sag and the 1 mm drop, by millimetres
    assert np.ptp(heights_after) < 1e-3  # no slow sinking
    assert min(uprights) > np.cos(np.radians(2.0))
    # settling, the sagging legs carry the trunk back by a centimetre; then nothing slides
    assert np.linalg.norm(data.qpos[:2] - start[:2]) < 0.02
    assert np.max(np.abs(data.site_xpos[sites, :2] - feet)) < 1e-3
    assert np.max(np.abs(data.ctrl * gear)) < 0.5 * 23.7  # far from the motors' limits
