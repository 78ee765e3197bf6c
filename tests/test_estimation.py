"""The state estimator: errors against the judge's truth, VIO latency, contact, Jacobians.

Bounds (about three times what is measured, so that a regression fails them) and why:

- standing, velocity RMS < 0.03 m/s (measured 0.008 on both robots, most of it in the first
  0.2 s, while the robot drops the millimetre the scene leaves under its feet and its springs
  settle; 0.006 and 0.002 after) and position RMS < 0.02 m (the VIO's noise is 0.01 m per
  axis; measured 0.003);
- pushed (a 1 Hz / 1.3 Hz sway of the base, as strong as each stand PD survives), velocity
  RMS < 0.08 m/s and peak < 0.2 m/s (measured 0.011 / 0.06 on Cassie, 0.026 / 0.09 on the
  quadruped, whose ball feet creep about 0.01 m/s in MuJoCo's soft contact while the sway
  shears them: the legs take the creep for base motion);
- orientation within 0.02 rad of the truth (the IMU's orientation noise is 0.002 rad per
  axis, measured 0.0035 RMS; the IMU site's placement is read from the description);
- on a board, the first estimate (before any VIO sample) stands the feet on its deck: base
  height within 0.03 m of the truth (measured 0.4 mm on Cassie's boards, 19 mm on the dog's
  skateboard, whose contact sites are its ball feet's centres), where a prior on the ground
  was 0.11-0.16 m low;
- from a prior 0.3 m off, the position converges below 0.02 m within a second with a VIO
  latency of 0 s as with 0.1 s, and as closely with either.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from ridempc.boards import load_board
from ridempc.controllers import StandController, make_controller
from ridempc.errors import ConfigError
from ridempc.estimation import EstimatorParameters, StateEstimator, estimate_board, lapack
from ridempc.estimation.imu import GRAVITY, ImuMount
from ridempc.estimation.leg_odometry import LegOdometryModel
from ridempc.estimation.state import JointValues
from ridempc.robots import load_robot
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.rotations import matrix_to_quaternion, quaternion_to_matrix
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.metrics import run_metrics
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from tests.helpers import LimpController, RecordingController, scenario

# horizontal sway force on the base [N/kg]: as strong as each robot's stand PD survives
SWAY = {"biped": 0.5, "quadruped": 2.0}  # [N/kg] by robot kind


def _sway(robot, amplitude: float):
    """From t = 0.5 s, a force of ``amplitude`` N/kg on the base at 1 Hz and 1.3 Hz."""
    mass = robot.mass

    def external(t: float, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        if t < 0.5:
            return
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, robot.params.base_body)
        force = [np.sin(2 * np.pi * t), 0.6 * np.sin(2 * np.pi * 1.3 * t + 1.0), 0.0]
        data.xfrc_applied[body, :3] += amplitude * mass * np.asarray(force)

    return external


class _Sealed:
    """Stands in for ``SensorPacket.truth``: any use of it fails the test."""

    def __getattr__(self, name: str):
        raise AssertionError(f"the estimator read the ground truth ('{name}')")


def _swaying_packets(robot, latency: float):
    """Packets (with truth, for the test only) of 2.5 s of stand under the sway."""
    controller = RecordingController(robot)
    sim = Simulation(
        build_scene(robot, DEFAULT_PHYSICS_HZ),
        controller,
        scenario(2.5, noise={"vio_latency": latency}),
        ground_truth=True,
        external=_sway(robot, SWAY[robot.params.kind]),
    )
    assert sim.run().status == "ok"
    return controller.packets


def _replay(robot, packets, prior_offset=(0.0, 0.0, 0.0)):
    """Run a fresh estimator on packets whose truth is sealed; errors against the truth.

    Returns:
        time [s], velocity error [m/s], position error [m], tilt-and-yaw error [rad].
    """
    estimator = StateEstimator(robot)
    first = packets[0]
    prior = first.truth.qpos[:3] + np.asarray(prior_offset)
    rows = []
    for k, packet in enumerate(packets):
        sealed = dataclasses.replace(packet, truth=_Sealed())
        if k == 0:
            state = estimator.reset(sealed, base_position=prior)
        else:
            state = estimator.update(sealed)
        qpos, qvel = packet.truth.qpos, packet.truth.qvel
        rotation_error = quaternion_to_matrix(qpos[3:7]).T @ state.rotation
        angle = np.arccos(np.clip((np.trace(rotation_error) - 1.0) / 2.0, -1.0, 1.0))
        rows.append(
            (
                packet.time,
                np.linalg.norm(state.base_velocity - qvel[:3]),
                np.linalg.norm(state.base_position - qpos[:3]),
                angle,
            )
        )
    return np.array(rows).T


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values**2)))


def test_standing_estimate_is_logged_and_accurate(robot) -> None:
    sim = Simulation(
        build_scene(robot, DEFAULT_PHYSICS_HZ),
        make_controller("stand", robot),
        scenario(2.5),
        ground_truth=False,
    )
    result = sim.run()
    assert result.status == "ok"
    log = result.log
    assert np.isnan(log["estimate_base_velocity"][0]).all()  # the judge logs before tick 0
    assert np.isfinite(log["estimate_base_velocity"][1:]).all()
    metrics = run_metrics(result, sim.scenario, robot)
    assert metrics["estimator_velocity_rmse"] < 0.03
    assert metrics["estimator_position_rmse"] < 0.02
    yaw_error = np.angle(np.exp(1j * (log["estimate_yaw"][1:] - log["yaw"][1:])))
    assert np.max(np.abs(yaw_error)) < 0.02


def test_a_controller_without_estimator_logs_none(robot) -> None:
    sim = Simulation(build_scene(robot, DEFAULT_PHYSICS_HZ), LimpController(robot), scenario(0.1))
    result = sim.run()
    assert "estimate_base_velocity" not in result.log
    assert "estimator_velocity_rmse" not in run_metrics(result, sim.scenario, robot)


def test_pushed_estimate_converges_with_or_without_vio_latency(robot) -> None:
    settled_rms = {}
    for latency in (0.0, 0.1):
        packets = _swaying_packets(robot, latency)
        time, velocity, position, angle = _replay(robot, packets, prior_offset=(0.3, -0.2, 0.0))
        assert position[0] > 0.3  # starts off by the prior's error
        settled = time >= 1.0
        assert _rms(velocity) < 0.08, latency
        assert np.max(velocity) < 0.2, latency
        assert np.max(position[settled]) < 0.02, latency
        assert np.max(angle) < 0.02, latency
        settled_rms[latency] = _rms(position[settled])
    # compared with the state at its capture stamp, a sample 0.1 s late does as well as a
    # prompt one (1.0 times the error on Cassie, 1.1 on the quadruped); compared with the
    # state at its arrival, it would lag the moving base (2.0 times on Cassie)
    assert settled_rms[0.1] < 1.3 * settled_rms[0.0] + 5e-4


def test_the_estimator_never_reads_the_truth(robot) -> None:
    controller = RecordingController(robot)
    Simulation(build_scene(robot, DEFAULT_PHYSICS_HZ), controller, scenario(0.2)).run()
    estimator = StateEstimator(robot)
    for packet in controller.packets:
        estimator.update(dataclasses.replace(packet, truth=_Sealed()))
    assert estimator.state is not None and np.isfinite(estimator.state.base_velocity).all()


def test_contact_is_lost_when_the_robot_is_lifted(robot) -> None:
    """An upward pull of 1.5 times the weight from t = 0.5 s lifts every foot off."""

    class Probe(StandController):
        def update(self, sensors, command):
            hold = super().update(sensors, command)
            flags[round(sensors.time, 3)] = self.estimator.state.contact
            return hold

    def lift(t: float, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        if t >= 0.5:
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, robot.params.base_body)
            data.xfrc_applied[body, 2] += 1.5 * robot.mass * 9.81

    flags: dict[float, np.ndarray] = {}
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ)
    Simulation(scene, Probe(robot), scenario(0.8), external=lift).run()
    assert all(flags[t].all() for t in flags if 0.2 <= t < 0.5)
    assert not any(flags[t].any() for t in flags if t >= 0.6)


def test_imu_mount_recovers_the_base_attitude() -> None:
    """A rotated, offset IMU: base orientation, body rates and the IMU point's acceleration."""
    rng = np.random.default_rng(0)
    rotation_bs = quaternion_to_matrix(rng.normal(size=4))
    mount = ImuMount(position=np.array([0.1, -0.05, 0.02]), rotation=rotation_bs)
    rotation_wb = quaternion_to_matrix(rng.normal(size=4))
    omega_b, accel_world = rng.normal(size=3), rng.normal(size=3)
    rotation_ws = rotation_wb @ rotation_bs
    attitude = mount.attitude(
        matrix_to_quaternion(rotation_ws),
        rotation_bs.T @ omega_b,
        rotation_ws.T @ (accel_world - GRAVITY),
    )
    np.testing.assert_allclose(attitude.rotation, rotation_wb, atol=1e-12)
    np.testing.assert_allclose(attitude.angular_velocity, omega_b, atol=1e-12)
    np.testing.assert_allclose(attitude.imu_acceleration, accel_world, atol=1e-12)


def test_imu_mount_is_read_from_the_description(robot) -> None:
    model = robot.mj_model
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, robot.params.imu_site)
    mount = ImuMount.from_pinocchio(build_pinocchio_robot(robot), robot.params.imu_site)
    np.testing.assert_allclose(mount.position, model.site_pos[site], atol=1e-12)
    np.testing.assert_allclose(
        mount.rotation, quaternion_to_matrix(model.site_quat[site]), atol=1e-12
    )


def _random_configuration(estimator: StateEstimator, rng: np.random.Generator) -> np.ndarray:
    """The stand keyframe with every encoder joint moved by up to 0.1 rad, loops closed."""
    model = estimator.model
    q = estimator.pinocchio.coordinates.qpos_to_pinocchio(estimator.robot.stand_qpos)
    q[:3] = rng.normal(size=3)
    q[3:7] = pin.Quaternion(pin.exp3(rng.normal(size=3) * 0.3)).coeffs()
    q[estimator.joints.encoder_q] += rng.uniform(-0.1, 0.1, estimator.joints.encoder_q.size)
    v = np.zeros(model.nv)
    if estimator.closure.active:
        estimator.closure.tolerance = 1e-12
        q, _ = estimator.closure.solve(model, estimator.data, q, v)
    return q


def test_loop_closure_jacobian_matches_finite_differences() -> None:
    estimator = StateEstimator(load_robot("cassie"))
    closure, model, data = estimator.closure, estimator.model, estimator.data
    assert closure.active  # the achilles four-bars
    rng = np.random.default_rng(1)
    eps = 1e-6
    for _ in range(5):
        q = _random_configuration(estimator, rng)
        assert closure.last_residual < 1e-11
        pin.computeJointJacobians(model, data, q)
        jacobian = closure.jacobian(model, data)
        numeric = np.empty_like(jacobian)
        for i in range(model.nv):
            step = np.zeros(model.nv)
            step[i] = eps
            pin.forwardKinematics(model, data, pin.integrate(model, q, step))
            plus = closure.residual(model, data)
            pin.forwardKinematics(model, data, pin.integrate(model, q, -step))
            minus = closure.residual(model, data)
            numeric[:, i] = (plus - minus) / (2 * eps)
        np.testing.assert_allclose(jacobian, numeric, atol=1e-7)
        # the completed velocity keeps the loops closed: r(q + v dt) = O(dt^2)
        v = np.zeros(model.nv)
        v[3:6] = rng.normal(size=3)
        v[estimator.joints.encoder_v] = rng.normal(size=estimator.joints.encoder_v.size)
        _, v = closure.solve(model, data, q, v)
        dt = 1e-5
        pin.forwardKinematics(model, data, pin.integrate(model, q, v * dt))
        assert np.max(np.abs(closure.residual(model, data))) < 1e-8


def test_unmeasured_joints_match_the_simulator() -> None:
    """Cassie's heel springs, solved from the rigid four-bar closure, against MuJoCo's.

    Exact where MuJoCo's loop is closed (the keyframe at t = 0). Under the robot's weight,
    MuJoCo's soft ``connect`` (solref 0.005 s) lets the rod stretch by about 2.5 mm, which
    the simulated heel spring takes up: there the rigid closure deflects the spring about
    twice as much, by up to 0.04 rad, in the same direction.
    """
    robot = load_robot("cassie")
    controller = RecordingController(robot)
    Simulation(
        build_scene(robot, DEFAULT_PHYSICS_HZ), controller, scenario(0.5), ground_truth=True
    ).run()
    estimator = StateEstimator(robot)
    model = robot.mj_model
    for packet in controller.packets[::50]:
        state = estimator.update(packet)
        for name in ("left_heel_spring", "right_heel_spring"):
            joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
            truth = packet.truth.qpos[model.jnt_qposadr[joint]]
            tolerance = 1e-3 if packet.time == 0.0 else 0.04
            assert state.joint_position[name] == pytest.approx(truth, abs=tolerance)
            assert np.sign(state.joint_position[name]) == np.sign(truth)


def test_foot_velocity_is_the_derivative_of_foot_position(robot) -> None:
    """:math:`w_i = J_i v` against finite differences of :math:`d_i(q)` along :math:`v`."""
    estimator = StateEstimator(robot)
    model, data, legs = estimator.model, estimator.data, estimator.legs
    rng = np.random.default_rng(2)
    dt = 1e-6
    for _ in range(5):
        q = _random_configuration(estimator, rng)
        v = np.zeros(model.nv)  # the base does not translate, as in the estimator
        v[3:] = rng.normal(size=model.nv - 3)
        pin.computeJointJacobians(model, data, q)
        reading = legs.read(model, data, v)
        pin.computeJointJacobians(model, data, pin.integrate(model, q, v * dt))
        plus = legs.read(model, data, v)
        pin.computeJointJacobians(model, data, pin.integrate(model, q, -v * dt))
        minus = legs.read(model, data, v)
        for name in ("foot_position", "site_position", "imu_position"):
            numeric = (getattr(plus, name) - getattr(minus, name)) / (2 * dt)
            analytic = getattr(reading, name.replace("position", "velocity"))
            np.testing.assert_allclose(analytic, numeric, atol=1e-6)


def test_board_from_feet_on_a_tilted_platform() -> None:
    rotation = quaternion_to_matrix(np.array([np.cos(0.2), 0.05, 0.08, np.sin(0.2)]))
    centre = np.array([1.0, -0.5, 0.12])
    corners = np.array([[0.2, 0.1, 0], [0.2, -0.1, 0], [-0.2, 0.1, 0], [-0.2, -0.1, 0]])
    points = centre + corners @ rotation.T
    omega, velocity = np.array([0.0, 0.0, 0.4]), np.array([0.8, 0.1, 0.0])
    velocities = velocity + np.cross(omega, points - centre)
    board = estimate_board(("a", "b", "c", "d"), points, velocities, forward=rotation[:, 0])
    roll = np.arctan2(rotation[2, 1], rotation[2, 2])
    pitch = -np.arcsin(rotation[2, 0])
    yaw = np.arctan2(rotation[1, 0], rotation[0, 0])
    np.testing.assert_allclose(board.position, centre, atol=1e-12)
    np.testing.assert_allclose([board.roll, board.pitch, board.yaw], [roll, pitch, yaw], atol=1e-9)
    np.testing.assert_allclose(board.velocity, velocity, atol=1e-12)
    assert board.yaw_rate == pytest.approx(0.4, rel=0.05)  # the deck is tilted a little


def test_board_roll_from_two_feet_side_by_side() -> None:
    """Two point feet across the deck: roll is the slope of the line through them."""
    left, right = np.array([0.0, 0.2, 0.1 + 0.02]), np.array([0.0, -0.2, 0.1 - 0.02])
    board = estimate_board(("l", "r"), np.array([left, right]), np.zeros((2, 3)), np.eye(3)[0])
    assert board.roll == pytest.approx(np.arctan2(0.04, 0.4), abs=1e-9)
    assert board.pitch == pytest.approx(0.0, abs=1e-12)
    assert board.position[2] == pytest.approx(0.1)


def test_a_line_foot_alone_on_its_platform_gives_the_platform_heading() -> None:
    """A toe line turned 0.3 rad right of the rider's forward (a Hovershoe that turned
    under its foot) is its own platform's heading; a line across the rider is not, nor one
    foot's line on a platform it shares."""
    heading = np.array([np.cos(-0.3), np.sin(-0.3), 0.0])
    front, back = 0.05 * heading + [0.0, 0.15, 0.11], -0.05 * heading + [0.0, 0.15, 0.11]
    rider_forward = np.array([1.0, 0.0, 0.0])
    points, still = np.array([front, back]), np.zeros((2, 3))
    board = estimate_board(("l",), points, still, rider_forward, own_platform=True)
    assert board.yaw == pytest.approx(-0.3, abs=1e-9)
    assert board.pitch == pytest.approx(0.0, abs=1e-12)
    backwards = estimate_board(("l",), points[::-1], still, rider_forward, own_platform=True)
    assert backwards.yaw == pytest.approx(-0.3, abs=1e-9)  # the sign follows the rider
    # one foot of two left in stance on a shared platform says nothing of its heading
    shared = estimate_board(("l",), points, still, rider_forward, own_platform=False)
    assert shared.yaw == pytest.approx(0.0, abs=1e-9)
    across = np.array([[0.0, 0.2, 0.1], [0.0, -0.2, 0.1]])
    sideways = estimate_board(("l", "r"), across, still, heading, own_platform=True)
    assert sideways.yaw == pytest.approx(-0.3, abs=1e-9)


def test_feet_on_a_platform_get_a_board_estimate() -> None:
    robot = load_robot("cyberdog2")
    feet = robot.params.foot_bodies
    controller = RecordingController(robot)
    Simulation(build_scene(robot, DEFAULT_PHYSICS_HZ), controller, scenario(0.3)).run()
    estimator = StateEstimator(robot, platforms=(feet,))
    for packet in controller.packets:
        state = estimator.update(packet)
    board = state.board
    assert board is not None and board.feet == feet
    assert abs(board.roll) < 0.02 and abs(board.pitch) < 0.02  # standing on flat ground
    assert board.position[2] == pytest.approx(0.019, abs=0.01)  # the ball feet's centres
    assert np.linalg.norm(board.velocity) < 0.05
    # a foot put on the ground (a push-off) leaves the board's estimate, then comes back;
    # the origin stays where the four feet put it (the three feet's centroid is 6 cm off)
    estimator.set_support(["RL_foot"])
    state = estimator.update(controller.packets[-1])
    assert state.board is not None and state.board.feet == ("FL_foot", "FR_foot", "RR_foot")
    assert np.linalg.norm(state.board.position - board.position) < 2e-3
    three = np.array([state.foot_position[feet.index(f)] for f in state.board.feet])
    assert np.linalg.norm(three.mean(axis=0)[:2] - board.position[:2]) > 0.04
    estimator.set_support([])
    assert estimator.update(controller.packets[-1]).board.feet == feet
    # a foot the schedule has in the air says nothing of the board even when it touches
    # down early (here it stands): left out, the origin stays put
    estimator.set_support([], swinging=["RL_foot"])
    state = estimator.update(controller.packets[-1])
    assert state.contact[feet.index("RL_foot")]
    assert state.board is not None and state.board.feet == ("FL_foot", "FR_foot", "RR_foot")
    assert np.linalg.norm(state.board.position - board.position) < 2e-3
    estimator.set_support([])
    assert estimator.update(controller.packets[-1]).board.feet == feet
    with pytest.raises(ConfigError, match="'RL_paw' is not a foot"):
        estimator.set_support(["RL_paw"])
    with pytest.raises(ConfigError, match="'RL_paw' is not a foot"):
        estimator.set_support([], swinging=["RL_paw"])


def test_filter_model_shapes_and_symmetry() -> None:
    params = EstimatorParameters()
    model = LegOdometryModel(4, params)
    stance = np.array([True, False, True, True])
    on_ground = np.array([True, True, False, False])
    F, b, Q = model.process(0.002, np.array([0.0, 0.0, 1.0]), stance, on_ground)
    assert F.shape == Q.shape == (30, 30) and b.shape == (30,)
    np.testing.assert_allclose(Q, Q.T)
    assert np.all(np.linalg.eigvalsh(Q) >= -1e-15)
    measurement = model.legs(np.zeros((4, 3)), np.zeros((4, 3)), stance)
    assert measurement.H.shape == (3 * (4 + 3), 30)  # positions of all feet, stance velocities
    assert measurement.gated is not None and measurement.gated.shape == (3, 3)


@pytest.mark.parametrize(
    ("robot_name", "board"),
    [("cassie", "hovershoes"), ("cassie", "segway"), ("cyberdog2", "skateboard")],
)
def test_first_estimate_on_a_board_stands_on_its_deck(robot_name: str, board: str) -> None:
    robot = load_robot(robot_name)
    loaded = load_board(board)
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, board=loaded)
    controller = make_controller("stand", robot, board)
    result = Simulation(scene, controller, scenario(duration=0.02)).run()
    log = result.log
    first = int(np.flatnonzero(np.isfinite(log["estimate_base_position"][:, 2]))[0])
    error = log["estimate_base_position"][first, 2] - log["base_position"][first, 2]
    assert abs(error) < 0.03, error


def test_leg_measurements_are_stacked_foot_by_foot() -> None:
    """Per foot its offset, then the negated velocity of a stance foot, in H's row order."""
    model = LegOdometryModel(3, EstimatorParameters())
    rng = np.random.default_rng(4)
    offsets, velocities = rng.normal(size=(3, 3)), rng.normal(size=(3, 3))
    stance = np.array([True, False, True])
    measurement = model.legs(offsets, velocities, stance)
    expected = [offsets[0], -velocities[0], offsets[1], offsets[2], -velocities[2]]
    np.testing.assert_array_equal(measurement.z, np.concatenate(expected))
    x = rng.normal(size=model.size)  # H picks p_i - p_S and p_S' - u_i in the same order
    predicted = [x[6:9] - x[:3], x[3:6] - x[9:12], x[12:15] - x[:3]]
    predicted += [x[18:21] - x[:3], x[3:6] - x[21:24]]
    np.testing.assert_allclose(measurement.H @ x, np.concatenate(predicted), atol=1e-15)


def test_lapack_helpers_give_numpys_results() -> None:
    rng = np.random.default_rng(5)
    a = rng.normal(size=(9, 9))
    a = a @ a.T + np.eye(9)
    b = rng.normal(size=(9, 4))
    x = lapack.solve(a, b)
    assert x.flags.c_contiguous
    np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=1e-13, atol=0.0)
    np.testing.assert_allclose(lapack.solve(a, b[:, 0]), np.linalg.solve(a, b[:, 0]), rtol=1e-13)
    points = rng.normal(size=(4, 3))
    for ours, numpys in zip(lapack.svd(points), np.linalg.svd(points), strict=True):
        np.testing.assert_allclose(ours, numpys, rtol=1e-13, atol=1e-15)
    with pytest.raises(np.linalg.LinAlgError):
        lapack.solve(np.zeros((3, 3)), np.ones(3))


def test_lapack_pinv_is_numpys_bit_for_bit() -> None:
    """The quadruped's deck fit (4 x 3, also rank-deficient) and a wide matrix."""
    rng = np.random.default_rng(6)
    for shape in ((4, 3), (4, 3), (3, 5)):
        a = rng.normal(size=shape)
        assert np.array_equal(lapack.pinv(a), np.linalg.pinv(a))
    a = rng.normal(size=(4, 3))
    a[:, 2] = a[:, 1]  # a repeated column: its smallest singular value cut off
    assert np.array_equal(lapack.pinv(a), np.linalg.pinv(a))


def test_joint_values_read_their_array_by_name() -> None:
    values = JointValues({"hip": 0, "knee": 1}, np.array([0.1, -0.2]))
    assert list(values) == ["hip", "knee"] and len(values) == 2
    assert values["knee"] == -0.2 and isinstance(values["knee"], float)
    assert dict(values) == {"hip": 0.1, "knee": -0.2}
    with pytest.raises(KeyError):
        values["ankle"]


def test_two_points_line_is_the_svds_to_rounding() -> None:
    """A board's two contact points (a line foot alone on a Hovershoe): their line, taken as
    d/|d| without an SVD, gives the normal and heading the SVD of the points gives."""
    from ridempc.estimation.board import _normal, _unit_rejection

    rng = np.random.default_rng(39)
    up = np.array([0.0, 0.0, 1.0])
    for _ in range(500):
        points = rng.normal(size=(2, 3)) * [0.1, 0.1, 0.01]
        centred = points - points.mean(axis=0)
        normal, line = _normal(centred, up)
        _, _, vt = lapack.svd(centred)
        assert line is not None
        np.testing.assert_allclose(abs(line @ vt[0]), 1.0, atol=1e-14)
        wanted, _ = _unit_rejection(up, vt[0])
        np.testing.assert_allclose(normal, wanted if wanted[2] >= 0.0 else -wanted, atol=1e-14)
    normal, line = _normal(np.zeros((2, 3)), up)  # one point twice: no line, the hint
    assert line is None and np.array_equal(normal, up)
