"""Controllers get sensors, not the simulator; ground truth only behind the flag."""

from __future__ import annotations

import numpy as np

from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from tests.helpers import RecordingController, scenario


def _packets(robot, seed: int = 0, ground_truth: bool = False, duration: float = 0.5):
    controller = RecordingController(robot)
    sim = Simulation(
        build_scene(robot, DEFAULT_PHYSICS_HZ),
        controller,
        scenario(duration),
        seed=seed,
        ground_truth=ground_truth,
    )
    result = sim.run()
    return controller.packets, result


def test_packets_hold_no_ground_truth_by_default(robot) -> None:
    packets, _ = _packets(robot)
    assert all(p.truth is None for p in packets)
    packets, _ = _packets(robot, ground_truth=True)
    assert all(p.truth is not None for p in packets)


def test_packet_contents_match_the_robot(robot) -> None:
    packets, _ = _packets(robot)
    last = packets[-1]
    assert last.joint_position.shape == (len(robot.encoder_joints),)
    assert last.motor_torque.shape == (len(robot.motors),)
    assert np.isclose(np.linalg.norm(last.imu.quaternion), 1.0)
    # standing: the accelerometer reads gravity's reaction, about +9.81 up in the body, on
    # average over the ride (its mean is g plus the change of the body's velocity over it);
    # single samples swing by several m/s^2 while a leaf-spring robot settles (Cassie)
    mean = np.mean([p.imu.linear_acceleration for p in packets], axis=0)
    assert 9.3 < np.linalg.norm(mean) < 10.3
    assert last.vio is not None


def test_encoders_track_the_true_joints_within_noise(robot) -> None:
    packets, _ = _packets(robot, ground_truth=True)
    model = robot.mj_model
    import mujoco

    adr = [
        model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)]
        for j in robot.encoder_joints
    ]
    errors = [np.abs(p.joint_position - p.truth.qpos[adr]).max() for p in packets]
    assert max(errors) < 1e-3  # 14-bit quantisation: half a step is 1.9e-4 rad


def test_runs_are_deterministic_for_a_seed(robot) -> None:
    a, ra = _packets(robot, seed=3)
    b, rb = _packets(robot, seed=3)
    c, _ = _packets(robot, seed=4)
    assert np.array_equal(a[-1].imu.angular_velocity, b[-1].imu.angular_velocity)
    assert np.array_equal(ra.log["qpos"], rb.log["qpos"])
    assert not np.array_equal(a[-1].imu.angular_velocity, c[-1].imu.angular_velocity)
