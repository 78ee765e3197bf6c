"""Cassie's standing controller (``pd``, Segway paper IV-A): kinematics, statics, gains and
physical outcomes on flat ground."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from ridempc.baselines.cassie_kinematics import SIDES, CassieKinematics
from ridempc.baselines.cassie_standing import CassieStanding
from ridempc.baselines.cassie_standing_gains import DEFAULT_GAINS_FILE, load_standing_gains
from ridempc.baselines.cassie_statics import FootLoad, StandingStatics
from ridempc.controllers import make_controller
from ridempc.errors import ConfigError
from ridempc.robots import load_robot
from ridempc.scenarios import resolve_scenario
from ridempc.scenarios.scenario import Scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import RunResult, Simulation
from tests.helpers import assert_gain_edit_refused

CONTACT_SITES = ("left_toe_front", "left_toe_back", "right_toe_front", "right_toe_back")


@pytest.fixture(scope="module")
def cassie():
    return load_robot("cassie")


@pytest.fixture(scope="module")
def kinematics(cassie) -> CassieKinematics:
    return CassieKinematics(cassie)


def _encoders_of(robot, qpos: np.ndarray) -> np.ndarray:
    """Encoder readings of a MuJoCo configuration (no noise)."""
    model = robot.mj_model
    joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in robot.encoder_joints]
    return np.array([qpos[model.jnt_qposadr[j]] for j in joints])


def _true_com_offsets(robot, qpos_rows: np.ndarray) -> np.ndarray:
    """True CoM minus the mean of the four contact sites, world frame [m], per logged row."""
    model = robot.mj_model
    data = mujoco.MjData(model)
    sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, s) for s in CONTACT_SITES]
    out = np.empty((len(qpos_rows), 3))
    for i, qpos in enumerate(qpos_rows):
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        out[i] = data.subtree_com[1] - data.site_xpos[sites].mean(axis=0)
    return out


def _roll(quaternions: np.ndarray) -> np.ndarray:
    w, x, y, z = quaternions.T
    return np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))


def _tilt(quaternions: np.ndarray) -> np.ndarray:
    w, x, y, z = quaternions.T
    return np.arccos(np.clip(1.0 - 2.0 * (x**2 + y**2), -1.0, 1.0))


def _ride(robot, scenario: Scenario) -> tuple[RunResult, Simulation]:
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ)
    simulation = Simulation(scene, make_controller("pd", robot), scenario)
    return simulation.run(), simulation


# ---------------------------------------------------------------- kinematics


@pytest.mark.parametrize("side", SIDES)
def test_leg_jacobian_matches_finite_differences(kinematics, side: str) -> None:
    rng = np.random.default_rng(4)
    step = 1e-6
    for _ in range(10):
        hip_pitch, knee = rng.uniform(-0.3, 1.0), rng.uniform(-2.6, -0.8)
        jac = kinematics.leg_jacobian(side, hip_pitch, knee)
        fd = np.column_stack(
            [
                kinematics.leg_coordinates(side, hip_pitch + step, knee)
                - kinematics.leg_coordinates(side, hip_pitch - step, knee),
                kinematics.leg_coordinates(side, hip_pitch, knee + step)
                - kinematics.leg_coordinates(side, hip_pitch, knee - step),
            ]
        ) / (2 * step)
        np.testing.assert_allclose(jac, fd, atol=1e-7)
        np.testing.assert_allclose(jac[:, 0], [0.0, 1.0], atol=1e-9)  # hip pitch turns the leg


@pytest.mark.parametrize("side", SIDES)
def test_virtual_leg_inverse_kinematics_round_trip(kinematics, side: str) -> None:
    table = kinematics.virtual_leg(side)
    rng = np.random.default_rng(5)
    for _ in range(50):
        hip_pitch, knee = rng.uniform(-0.5, 1.2), rng.uniform(-2.7, -0.7)
        length, angle = kinematics.leg_coordinates(side, hip_pitch, knee)
        np.testing.assert_allclose(table.inverse(length, angle), (hip_pitch, knee), atol=1e-5)
        np.testing.assert_allclose(table.forward(hip_pitch, knee), (length, angle), atol=1e-6)


@pytest.mark.parametrize("side", SIDES)
def test_eq3_closes_the_achilles_four_bar(kinematics, side: str) -> None:
    """With the springs at rest and tarsus = 13 deg - knee (eq. 3), the heel-spring end lies
    on the achilles rod's sphere about its hip anchor: exactly at knee -45 deg, within 1 mm
    over the standing range."""
    model = kinematics.model
    data = model.createData()
    anchor = model.getFrameId(f"{side}_achilles_rod", pin.FrameType.BODY)
    rod_end = model.getFrameId(f"{side}_achilles_rod_end")
    heel_end = model.getFrameId(f"{side}_heel_spring_end")
    rod_length = np.linalg.norm(model.frames[rod_end].placement.translation)
    for degrees, tolerance in ((-45.0, 1e-6), (-60.0, 1e-3), (-70.0, 1e-3), (-100.0, 1.5e-3)):
        _, q = kinematics.rigid_leg(side, 0.3, np.radians(degrees))
        pin.framesForwardKinematics(model, data, q)  # own data: rigid_leg's is shared
        reach = data.oMf[heel_end].translation - data.oMf[anchor].translation
        assert abs(np.linalg.norm(reach) - rod_length) < tolerance


def test_com_velocity_matches_finite_differences(cassie, kinematics) -> None:
    rng = np.random.default_rng(6)
    q0 = _encoders_of(cassie, cassie.stand_qpos)
    q0 = q0 + rng.normal(0.0, 0.05, q0.size)
    qd = rng.normal(0.0, 0.5, q0.size)
    gyro = np.array([0.4, -0.3, 0.0])  # roll and pitch rates from upright keep the yaw at zero
    dt = 1e-6

    def offset(t: float) -> np.ndarray:
        rotation = pin.exp3(gyro * t)
        x, y, z, w = pin.Quaternion(rotation).coeffs()
        state = kinematics.measure(t, np.array([w, x, y, z]), gyro, q0 + qd * t, qd)
        return state.com_offset

    state = kinematics.measure(0.0, np.array([1.0, 0.0, 0.0, 0.0]), gyro, q0, qd)
    fd = (offset(dt) - offset(-dt)) / (2 * dt)
    np.testing.assert_allclose(state.com_velocity, fd, atol=1e-6)


def test_statics_point_jacobian_matches_finite_differences(cassie, kinematics) -> None:
    """The generalised force of a point load is the transpose of the point's Jacobian: the
    force's virtual work under a joint displacement, by finite differences."""
    statics = StandingStatics(kinematics)
    model = kinematics.model
    data = model.createData()
    q = kinematics.pinocchio.coordinates.qpos_to_pinocchio(cassie.stand_qpos)
    frame = kinematics.legs["left"].foot_frame
    lever = np.array([0.03, -0.02, 0.01])  # a point fixed on the foot, foot frame
    pin.framesForwardKinematics(model, data, q)
    placement = data.oMf[frame]
    force = np.array([3.0, -2.0, 150.0])
    load = {"left": FootLoad(point=placement.act(lever), force=force)}
    gravity = pin.computeGeneralizedGravity(model, model.createData(), q)
    generalised = gravity - statics.generalised_torque(q, load)  # = J_c^T f
    step = 1e-6
    for index in kinematics.legs["left"].v:
        dv = np.zeros(model.nv)
        dv[index] = step
        points = []
        for sign in (1.0, -1.0):
            pin.framesForwardKinematics(model, data, pin.integrate(model, q, sign * dv))
            points.append(data.oMf[frame].act(lever))
        work = force @ (points[0] - points[1]) / (2 * step)
        assert generalised[index] == pytest.approx(work, abs=1e-5)


# ---------------------------------------------------------------- gain file


def test_default_gains_load(cassie) -> None:
    gains = load_standing_gains()
    assert gains.com_x.kp > 0 and gains.roll.kp > 0
    with pytest.raises(ValueError):
        gains.com_x.kp = 1.0  # type: ignore[misc]  # frozen


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("kp = 3.0               # [-]", "kp = -3.0", "com_x.kp"),
        ("filter_hz = 10.0", "filter_hz = 10.0\nkq = 1.0", "roll.kq"),
        ("max_length = 0.95", "max_length = 0.4", "legs"),
        ("knee = { kp = 3000.0, kd = 25.0 }", 'knee = { kp = "stiff", kd = 25.0 }', "knee.kp"),
    ],
)
def test_bad_gain_file_is_refused_naming_the_field(cassie, tmp_path, old, new, field) -> None:
    assert_gain_edit_refused(
        DEFAULT_GAINS_FILE,
        tmp_path,
        old,
        new,
        field,
        lambda path: CassieStanding(cassie, gains=path),
    )


def test_pd_is_cassie_standing_and_refuses_other_robots(cassie) -> None:
    controller = make_controller("pd", cassie)
    assert isinstance(controller, CassieStanding)
    assert not controller.uses_ground_truth
    with pytest.raises(ConfigError, match="cyberdog2.*left_hip_roll"):
        CassieStanding(load_robot("cyberdog2"))


# ---------------------------------------------------------------- closed loop


def test_stands_still_with_the_com_over_the_feet(cassie) -> None:
    scenario = resolve_scenario("stand-still").with_duration(4.0)
    result, simulation = _ride(cassie, scenario)
    assert result.status == "ok", result.fall_reason or result.error
    log = result.log
    settled = log["time"] >= 3.0
    target = load_standing_gains().com_x.target
    com = _true_com_offsets(cassie, log["qpos"][settled])
    assert np.max(np.abs(com[:, 0] - target)) < 0.01  # CoM x within 1 cm of its target
    assert np.max(np.abs(com[:, 1])) < 0.01  # centred sideways
    assert np.max(np.abs(_roll(log["base_quaternion"][settled]))) < np.radians(1.0)
    height = log["base_position"][settled, 2]
    assert np.ptp(height) < 0.005 and height[-1] > 0.95
    # the feedforward (inverse statics) carries the weight: the PD adds little to the knees
    assert simulation.driver is not None and simulation.driver.command is not None
    feedforward = simulation.driver.command.torque
    total = simulation.driver.torque(simulation.scene.data)
    knees = [i for i, m in enumerate(cassie.motors) if m.joint.endswith("knee")]
    assert np.all(np.abs(total[knees] - feedforward[knees]) < 0.2 * np.abs(total[knees]))


def test_survives_the_library_push(cassie) -> None:
    result, _ = _ride(cassie, resolve_scenario("push"))
    assert result.status == "ok", result.fall_reason or result.error
    log = result.log
    assert np.max(_tilt(log["base_quaternion"])) < np.radians(5.0)
    after = log["time"] >= 8.0  # 2 s after the sideways push
    assert np.max(np.abs(_roll(log["base_quaternion"][after]))) < np.radians(1.0)
    com = _true_com_offsets(cassie, log["qpos"][after])
    assert np.max(np.abs(com[:, 0] - load_standing_gains().com_x.target)) < 0.015


def test_survives_pushes_the_joint_pd_does_not(cassie) -> None:
    """2 N/kg sideways for 0.2 s: the `stand` joint-PD hold falls from about 1.4 N/kg."""
    scenario = Scenario(
        name="strong-push",
        duration=4.0,
        disturbances=[dict(t=1.5, force=(0.0, 2.0, 0.0), per_kg=True, duration=0.2)],
    )
    result, _ = _ride(cassie, scenario)
    assert result.status == "ok", result.fall_reason or result.error
    assert abs(_roll(result.log["base_quaternion"][-1:])[0]) < np.radians(2.0)
