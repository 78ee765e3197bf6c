"""One description, two engines: Pinocchio and MuJoCo must agree on the same MJCF file.

For 20 seeded random configurations per robot: total mass, centre of mass, joint-space mass
matrix (in Pinocchio's velocity coordinates, M_pin = T^T M_mj T) and the world positions of
the contact points and foot bodies agree to a relative error below 1e-6.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin

from ridempc.robots.pinocchio_model import build_pinocchio_robot

N_CONFIGURATIONS = 20
TOLERANCE = 1e-6


def _random_qpos(model: mujoco.MjModel, rng: np.random.Generator) -> np.ndarray:
    qpos = model.qpos0.copy()
    for j in range(model.njnt):
        a = model.jnt_qposadr[j]
        kind = model.jnt_type[j]
        if kind == mujoco.mjtJoint.mjJNT_FREE:
            qpos[a : a + 3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            qpos[a + 3 : a + 7] = quat / np.linalg.norm(quat)
        elif kind == mujoco.mjtJoint.mjJNT_BALL:
            quat = rng.normal(size=4)
            qpos[a : a + 4] = quat / np.linalg.norm(quat)
        else:
            low, high = model.jnt_range[j] if model.jnt_limited[j] else (-np.pi, np.pi)
            qpos[a] = rng.uniform(low, high)
    return qpos


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1.0))


def test_pinocchio_and_mujoco_agree(robot) -> None:
    model = robot.mj_model
    data = mujoco.MjData(model)
    pinned = build_pinocchio_robot(robot)
    pmodel = pinned.model
    pdata = pmodel.createData()
    coords = pinned.coordinates
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, robot.params.base_body)
    sites = [
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, s) for s in robot.params.contact_sites
    ]
    feet = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in robot.params.foot_bodies]
    site_frames = [pinned.frame_id(s) for s in robot.params.contact_sites]
    foot_frames = [pinned.frame_id(b) for b in robot.params.foot_bodies]
    assert min(sites) >= 0 and min(feet) >= 0

    mass_pin = pin.computeTotalMass(pmodel)
    assert abs(mass_pin - robot.mass) / robot.mass < TOLERANCE

    rng = np.random.default_rng(20261122)
    for _ in range(N_CONFIGURATIONS):
        qpos = _random_qpos(model, rng)
        data.qpos[:] = qpos
        mujoco.mj_forward(model, data)
        q = coords.qpos_to_pinocchio(qpos)

        com_pin = pin.centerOfMass(pmodel, pdata, q)
        assert _relative(com_pin, data.subtree_com[base]) < TOLERANCE

        mass_mj = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, mass_mj)
        transform = coords.velocity_map(qpos)
        pin.crba(pmodel, pdata, q)
        mass_pin_matrix = np.triu(pdata.M) + np.triu(pdata.M, 1).T
        assert _relative(mass_pin_matrix, transform.T @ mass_mj @ transform) < TOLERANCE

        pin.framesForwardKinematics(pmodel, pdata, q)
        for site, frame in zip(sites, site_frames, strict=True):
            assert _relative(pdata.oMf[frame].translation, data.site_xpos[site]) < TOLERANCE
        for body, frame in zip(feet, foot_frames, strict=True):
            assert _relative(pdata.oMf[frame].translation, data.xpos[body]) < TOLERANCE


def test_coordinate_maps_round_trip(robot) -> None:
    coords = build_pinocchio_robot(robot).coordinates
    rng = np.random.default_rng(1)
    qpos = _random_qpos(robot.mj_model, rng)
    qvel = rng.normal(size=robot.mj_model.nv)
    assert np.allclose(coords.qpos_from_pinocchio(coords.qpos_to_pinocchio(qpos)), qpos)
    v = coords.qvel_to_pinocchio(qpos, qvel)
    assert np.allclose(coords.qvel_from_pinocchio(qpos, v), qvel)
    assert np.allclose(coords.velocity_map(qpos) @ v, qvel)


def test_motor_limits_reach_pinocchio(robot) -> None:
    pmodel = build_pinocchio_robot(robot).model
    for motor in robot.motors:
        idx = pmodel.joints[pmodel.getJointId(motor.joint)].idx_v
        assert pmodel.effortLimit[idx] == motor.torque_limit > 0
        assert pmodel.velocityLimit[idx] == motor.speed_limit > 0
