"""Motors as their makers specify them: the torque-speed curve, the torque delay, the robot
descriptions that carry them, and a robot that still stands with them."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.controllers import make_controller
from ridempc.errors import ConfigError
from ridempc.robots import TorqueSpeedCurve, load_robot, load_robot_parameters
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.motors import MotorCommand, MotorDriver, delay_steps
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation


@pytest.fixture
def curve(robot) -> TorqueSpeedCurve:
    return TorqueSpeedCurve.of(robot.motors)


def _driver(robot) -> tuple[MotorDriver, object]:
    """A driver on the robot's own model (no floor) at the default physics rate."""
    import mujoco

    model = robot.spec().compile()
    model.opt.timestep = 1.0 / DEFAULT_PHYSICS_HZ
    data = mujoco.MjData(model)
    return MotorDriver(model, robot.motors, np.arange(model.nu)), data


def _torque_command(torque: np.ndarray) -> MotorCommand:
    zero = np.zeros_like(torque)
    return MotorCommand(torque, zero, zero, zero, zero)


def test_full_torque_up_to_the_corner(curve) -> None:
    for share in (0.0, 0.3, 0.999):
        for sign in (1.0, -1.0):
            speed = sign * share * curve.corner_speed
            assert np.array_equal(curve.limit(speed), curve.peak)


def test_no_torque_at_and_beyond_no_load(curve) -> None:
    for share in (1.0, 1.2, 5.0):
        for sign in (1.0, -1.0):
            assert np.all(curve.limit(sign * share * curve.no_load_speed) == 0.0)


def test_linear_between_corner_and_no_load(curve) -> None:
    for share in (0.1, 0.25, 0.5, 0.9):
        speed = curve.corner_speed + share * (curve.no_load_speed - curve.corner_speed)
        assert np.allclose(curve.limit(speed), (1.0 - share) * curve.peak, rtol=1e-12)


def test_braking_is_limited_as_driving(curve) -> None:
    """The limit depends on |speed| only (cassie-mujoco-sim's motor model): a torque against
    the motion is cut as much as one along it."""
    rng = np.random.default_rng(0)
    for _ in range(20):
        speed = rng.uniform(-1.2, 1.2, curve.peak.size) * curve.no_load_speed
        limit = curve.limit(speed)
        assert np.array_equal(limit, curve.limit(-speed))
        big = 10.0 * curve.peak
        assert np.array_equal(curve.clip(-np.sign(speed) * big, speed), -np.sign(speed) * limit)
        assert np.array_equal(curve.clip(np.sign(speed) * big, speed), np.sign(speed) * limit)


def test_cassie_follows_agility_motor_model() -> None:
    """2 peak (1 - |speed| / no-load speed), within [0, peak] (cassie-mujoco-sim's motor model)."""
    curve = TorqueSpeedCurve.of(load_robot("cassie").motors)
    rng = np.random.default_rng(1)
    for _ in range(20):
        w = rng.uniform(-1.1, 1.1, curve.peak.size) * curve.no_load_speed
        agility = np.clip(2.0 * curve.peak * (1.0 - np.abs(w) / curve.no_load_speed), 0, None)
        assert np.allclose(curve.limit(w), np.minimum(agility, curve.peak), atol=1e-9)


def test_cyberdog2_follows_the_cybergear_datasheet() -> None:
    """12 N m peak; the envelope passes the rated 4 N m at 240 rpm and ends at 296 rpm."""
    curve = TorqueSpeedCurve.of(load_robot("cyberdog2").motors)
    rpm = 2.0 * np.pi / 60.0
    assert np.allclose(curve.peak, 12.0, atol=1e-3)
    assert np.allclose(curve.no_load_speed, 296 * rpm, atol=0.01)
    assert np.allclose(curve.limit(np.full(curve.peak.size, 240 * rpm)), 4.0, atol=0.01)


def test_each_description_carries_its_curve(robot) -> None:
    for motor in robot.motors:
        assert 0.0 < motor.full_torque_fraction < 1.0
        assert motor.torque_delay >= 0.0
    if robot.name == "cassie":  # Agility's figures: half the no-load speed, 3 ms
        assert {(m.full_torque_fraction, m.torque_delay) for m in robot.motors} == {(0.5, 0.003)}


@pytest.mark.parametrize("field", ["full_torque_fraction", "torque_delay"])
def test_a_description_without_its_curve_is_refused(robot, tmp_path, field: str) -> None:
    text = (robot.folder / "robot.toml").read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith(f"{field} =")]
    path = tmp_path / "robot.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=field):
        load_robot_parameters(path)


@pytest.mark.parametrize(
    ("field", "value"),
    [("full_torque_fraction", "1.0"), ("full_torque_fraction", "0.0"), ("torque_delay", "-0.001")],
)
def test_a_curve_out_of_range_is_refused(robot, tmp_path, field: str, value: str) -> None:
    text = (robot.folder / "robot.toml").read_text(encoding="utf-8")
    lines = [
        f"{field} = {value}" if line.startswith(f"{field} =") else line
        for line in text.splitlines()
    ]
    path = tmp_path / "robot.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=field):
        load_robot_parameters(path)


def test_delay_in_whole_physics_steps() -> None:
    assert delay_steps(0.003, 1.0 / 2000) == 6  # Agility's 6 cycles of 0.5 ms
    assert delay_steps(0.003, 1.0 / 1500) == 5  # 4.5 steps: never shorter than 3 ms
    assert delay_steps(0.002, 1.0 / 1500) == 3  # a whole number of steps stays it
    assert delay_steps(0.0, 1.0 / 1500) == 0


def test_a_step_command_reaches_the_joint_after_the_delay(robot) -> None:
    driver, data = _driver(robot)
    delay = driver.delay
    step = 0.1 * driver.curve.peak
    driver.command = _torque_command(np.zeros_like(step))
    for _ in range(10):
        driver.apply(data)
    driver.command = _torque_command(step)
    gear = np.array([m.gear for m in robot.motors])
    for k in range(int(delay.max()) + 3):
        driver.apply(data)
        late = k < delay
        assert np.array_equal(data.ctrl * gear == 0.0, late), k
        assert np.allclose(data.ctrl[~late] * gear[~late], step[~late])
        assert np.array_equal(driver.torque(data), data.ctrl * gear)
    assert np.all(delay == delay_steps(robot.motors[0].torque_delay, 1.0 / DEFAULT_PHYSICS_HZ))


def test_each_motor_waits_its_own_delay(robot) -> None:
    """Motors with different delays (0 to 5 steps) in one driver: each torque of a ramp
    reaches its joint exactly its own motor's delay later."""
    import dataclasses

    import mujoco

    model = robot.spec().compile()
    model.opt.timestep = 1.0 / DEFAULT_PHYSICS_HZ
    data = mujoco.MjData(model)
    motors = tuple(
        dataclasses.replace(m, torque_delay=(k % 4) * 0.0011) for k, m in enumerate(robot.motors)
    )
    driver = MotorDriver(model, motors, np.arange(model.nu))
    assert len(set(driver.delay.tolist())) > 2
    gear = np.array([m.gear for m in motors])
    unit = 1e-3 * driver.curve.peak
    for k in range(20):
        driver.command = _torque_command((k + 1) * unit)  # torque k + 1 computed at step k
        driver.apply(data)
        sent = np.maximum(k - driver.delay + 1, 0)  # the step's torque, or none yet
        np.testing.assert_allclose(data.ctrl * gear, sent * unit, rtol=1e-12, atol=0.0)


def test_the_driver_applies_the_curve(robot) -> None:
    driver, data = _driver(robot)
    dof = driver._dof
    big = 5.0 * driver.curve.peak
    # joints turning at 0.9 of their no-load speed, half of them each way, asked to brake
    speed = 0.9 * driver.curve.no_load_speed * np.where(np.arange(big.size) % 2, 1.0, -1.0)
    driver.command = _torque_command(-np.sign(speed) * big)
    for _ in range(int(driver.delay.max()) + 1):
        data.qvel[dof] = speed
        driver.apply(data)
    assert np.allclose(driver.torque(data), -np.sign(speed) * driver.curve.limit(speed))
    assert np.all(driver.torque(data) != 0.0)
    assert np.all(np.abs(driver.demand) > driver.available)  # the curve cut it


def test_scale_torque_limit_scales_the_peak(robot) -> None:
    driver, _ = _driver(robot)
    before = driver.curve
    driver.scale_torque_limit(0.5)
    assert np.allclose(driver.curve.peak, 0.5 * before.peak)
    assert np.array_equal(driver.curve.no_load_speed, before.no_load_speed)
    speed = before.corner_speed + 0.5 * (before.no_load_speed - before.corner_speed)
    assert np.allclose(driver.curve.limit(speed), 0.5 * before.limit(speed))


def test_a_standing_robot_still_stands(robot) -> None:
    """The stand controller, through the curve and the delay, 3 s on flat ground."""
    scenario = resolve_scenario("stand-still").with_duration(3.0)
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ)
    sim = Simulation(scene, make_controller("stand", robot), scenario)
    result = sim.run()
    assert result.status == "ok", result.fall_reason or result.error
    height = result.log["base_position"][:, 2]
    assert abs(height[-1] - height[0]) < 0.03
    assert sim.driver is not None and np.all(sim.driver.delay >= 0)
    # the log carries what the curve allowed next to what the drivers asked for
    assert result.log["motor_available"].shape == result.log["motor_demand"].shape


def test_the_wbc_torque_bounds_follow_the_curve(robot) -> None:
    """The whole-body QP's torque rows: the curve's limits at the motors' present speeds."""
    from ridempc.wbc.constraints import TorqueSpeedConstraint
    from ridempc.wbc.model import WholeBodyModel

    model = WholeBodyModel(robot)
    curve = TorqueSpeedCurve.of(robot.motors)
    constraint = TorqueSpeedConstraint(model.layout, curve, model.motor_v)
    rng = np.random.default_rng(2)
    q = model.pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
    for _ in range(5):
        v = rng.normal(size=model.model.nv)
        v[model.motor_v] = rng.uniform(-1.2, 1.2, curve.peak.size) * curve.no_load_speed
        terms = model.update(q, v)
        block = constraint.compute_qp_constraint(terms, None, None)  # rows read no targets
        limit = curve.limit(v[model.motor_v])
        assert np.array_equal(block.upper, limit) and np.array_equal(block.lower, -limit)
        rows, columns = np.nonzero(block.matrix)
        assert np.array_equal(rows, np.arange(curve.peak.size))
        assert np.array_equal(columns, model.layout.torque.start + np.arange(curve.peak.size))
