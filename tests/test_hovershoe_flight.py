"""The hovershoe rider's flight detector: a foot unloaded when its shin spring relaxes."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.baselines.cassie_hovershoes import CassieHovershoes
from ridempc.baselines.cassie_kinematics import SIDES, LegIndices
from ridempc.baselines.hovershoe_flight import unloaded_feet
from ridempc.baselines.hovershoe_gains import FlightGains, load_hovershoes_gains
from ridempc.controllers import make_controller
from ridempc.errors import ConfigError
from ridempc.robots import load_robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.sensors import ImuReading, SensorPacket


def test_standing_deflection_is_loaded_and_relaxed_spring_unloaded() -> None:
    flags = unloaded_feet(np.array([-0.039, -0.004]), 0.012)
    assert flags.tolist() == [False, True]


def test_zero_threshold_never_unloads() -> None:
    assert not unloaded_feet(np.array([0.0, -0.0001]), 0.0).any()


def test_gain_file_sets_flight_and_default_is_off() -> None:
    gains = load_hovershoes_gains()
    assert 0.0 < gains.flight.unloaded_shin < 0.039  # below the standing deflection
    assert FlightGains().unloaded_shin == 0.0


def test_negative_threshold_is_refused() -> None:
    with pytest.raises((ConfigError, ValueError)):
        FlightGains(unloaded_shin=-0.01)


def _packet(robot, time: float, shin: float | None = None) -> SensorPacket:
    """A still packet at Cassie's standing keyframe, the shin springs optionally set [rad]."""
    model = robot.mj_model
    names = robot.encoder_joints
    position = np.array([robot.stand_qpos[model.jnt_qposadr[model.joint(n).id]] for n in names])
    if shin is not None:
        for side in ("left", "right"):
            position[names.index(f"{side}_shin")] = shin
    return SensorPacket(
        time=time,
        imu=ImuReading(
            quaternion=np.array([1.0, 0.0, 0.0, 0.0]),
            angular_velocity=np.zeros(3),
            linear_acceleration=np.array([0.0, 0.0, 9.81]),
        ),
        joint_position=position,
        joint_velocity=np.zeros(len(names)),
        motor_torque=np.zeros(len(robot.motors)),
        vio=None,
    )


def test_unloaded_foot_has_its_ankle_held_without_torque() -> None:
    """Relaxed shin springs: no fed-forward toe torque, the toe stiff about the foot's
    last loaded pitch; loaded springs: the paper's toe-torque law untouched."""
    robot = load_robot("cassie")
    controller = make_controller("pd", robot, "hovershoes")
    assert isinstance(controller, CassieHovershoes)
    flight = controller.rider_gains.flight
    controller.update(_packet(robot, 0.0, shin=-0.04), Command())
    loaded = controller.update(_packet(robot, 0.002, shin=-0.04), Command())
    unloaded = controller.update(_packet(robot, 0.004, shin=0.0), Command())
    toes = [controller.kinematics.legs[s].motors[LegIndices.TOE] for s in SIDES]
    for toe in toes:
        assert loaded.kp[toe] == 0.0  # torque-driven toe while loaded
        assert unloaded.torque[toe] == 0.0
        assert unloaded.kp[toe] == flight.kp_toe
    assert controller.diagnostics()["left_unloaded"] == 1.0


def test_unloaded_leg_reaches_down_and_comes_back_at_the_posture_rate() -> None:
    """A foot whose shoe falls away: after ``reach_delay`` its leg lengthens at
    ``extend_speed`` up to ``max_extension``; loaded again, it shortens at the posture's
    slew rate."""
    robot = load_robot("cassie")
    controller = make_controller("pd", robot, "hovershoes")
    assert isinstance(controller, CassieHovershoes)
    flight, legs = controller.rider_gains.flight, controller.gains.legs
    assert flight.extend_speed > 0.0 and flight.max_extension > 0.0
    dt = 0.002

    def length(time: float, shin: float) -> float:
        controller.update(_packet(robot, time, shin=shin), Command())
        return controller.diagnostics()["left_leg_length_target"]

    controller.update(_packet(robot, 0.0, shin=-0.04), Command())
    standing = length(dt, -0.04)
    reach = flight.reach_delay + 0.02  # [s] of flight, short of the longest reach
    for k in range(round(reach / dt)):
        reached = length(2 * dt + (k + 1) * dt, 0.0)
    assert reached - standing == pytest.approx(
        0.02 * flight.extend_speed, abs=3 * dt * flight.extend_speed
    )
    back = 0.05  # [s] loaded again
    t = 2 * dt + reach
    for k in range(round(back / dt)):
        returned = length(t + (k + 1) * dt, -0.04)
    assert reached - returned == pytest.approx(legs.max_speed * back, rel=0.15)
    for k in range(round(1.0 / dt)):  # a long flight: the reach stops at its longest
        longest = length(t + back + (k + 1) * dt, 0.0)
    assert longest - standing == pytest.approx(flight.max_extension, abs=0.01)


def test_a_stamping_foot_does_not_ratchet_its_leg_longer() -> None:
    """Unloaded for less than ``reach_delay`` at a time, then loaded: the leg keeps its
    length (a reach at each short unload, undone at the slow slew rate, would ratchet)."""
    robot = load_robot("cassie")
    controller = make_controller("pd", robot, "hovershoes")
    assert isinstance(controller, CassieHovershoes)
    dt, half = 0.002, 0.5 * controller.rider_gains.flight.reach_delay
    controller.update(_packet(robot, 0.0, shin=-0.04), Command())
    controller.update(_packet(robot, dt, shin=-0.04), Command())
    standing = controller.diagnostics()["left_leg_length_target"]
    t = dt
    for _ in range(10):  # 10 stamps, each unloaded for half the delay
        for shin in (0.0, -0.04):
            for _ in range(round(half / dt)):
                t += dt
                controller.update(_packet(robot, t, shin=shin), Command())
    assert controller.diagnostics()["left_leg_length_target"] == pytest.approx(standing, abs=1e-3)
