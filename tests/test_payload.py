"""The payload estimate's physics (:mod:`ridempc.mpc.payload`) and the lighter rider's knob.

- A known extra mass at a known place on Cassie standing still: the loads, ankle torques and
  IMU reading it makes are synthesised from statics (the sites' vertical forces carrying the
  weight with their centre of pressure under the true centre of mass), fed to the estimator
  with its estimate put back into the model each MPC step, as the rider does: the mass is
  recovered less the dead band, and the model's centre of mass moves onto the true one.
- The same payload on a stance swaying sideways at the balance's frequency, the centre of
  pressure leading the centre of mass by the zero-moment point's term, while the backup
  rides (the estimate in no loop): the running mean with the sway's acceleration term
  recovers mass and offset within half a second, where the slow closed-loop integration
  has taken up a fraction of the offset.
- The payload stage passes the estimator the backup's riding and the estimate's velocity.
- A negative payload scales the rider's bodies: the robot's mass is that much less, its
  centre of mass where it was.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from ridempc.controllers import make_controller
from ridempc.errors import ConfigError
from ridempc.mpc.handover import RETURN_DWELL_S
from ridempc.mpc.payload import (
    GRAVITY,
    MASS_DEADBAND,
    MEAN_DEADBAND_M,
    SHIFT_DEADBAND_M,
    PayloadEstimate,
    PayloadEstimator,
)
from ridempc.mpc.readiness import start_readiness
from ridempc.pair_description import load_pair_description
from ridempc.robots import load_robot
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.scenarios.scenario import ParameterChange, Scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.sensors import ImuReading
from ridempc.sim.simulation import Simulation

MPC_DT = 1.0 / 30.0  # [s] the rider's MPC step
TICKS = 15  # control ticks per MPC step


def _stance_readings(
    estimator: PayloadEstimator, n_motors: int, q: np.ndarray, mass: float, com: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each foot's load fraction and the motor torques of a static stance at ``q`` carrying
    ``mass`` [kg] with its centre of mass at ``com`` [m] (world): the sites' vertical forces
    the least-norm ones with that sum and that centre of pressure."""
    model, data = estimator.model, estimator.data
    pin.computeJointJacobians(model, data, q)
    gravity = pin.computeGeneralizedGravity(model, data, q)
    feet = estimator.legs.feet
    sites = [f for foot in feet for f in foot.sites]
    points = np.array([pin.updateFramePlacement(model, data, f).translation for f in sites])
    rows = np.vstack([np.ones(len(sites)), points[:, 0], points[:, 1]])
    weight = mass * GRAVITY
    forces = np.linalg.lstsq(rows, weight * np.array([1.0, com[0], com[1]]), rcond=None)[0]
    assert np.all(forces > 0.0), "the centre of mass must stand inside the stance"
    loads, torque, k = np.zeros(len(feet)), np.zeros(n_motors), 0
    for i, (foot, ankle) in enumerate(zip(feet, estimator.ankles, strict=True)):
        share = forces[k : k + len(foot.sites)]
        loads[i] = share.sum() / estimator.share
        if ankle is not None:
            v, motor = ankle
            arms = [
                pin.getFrameJacobian(model, data, f, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[2, v]
                for f in foot.sites
            ]
            torque[motor] = gravity[v] - float(np.dot(arms, share))
        k += len(foot.sites)
    return loads, torque


def _standing_imu(q: np.ndarray) -> ImuReading:
    """The IMU of a rider at rest in the configuration ``q``: gravity's specific force."""
    rotation = pin.XYZQUATToSE3(q[:7]).rotation
    quaternion = pin.Quaternion(rotation)
    return ImuReading(
        quaternion=np.array([quaternion.w, quaternion.x, quaternion.y, quaternion.z]),
        angular_velocity=np.zeros(3),
        linear_acceleration=rotation.T @ np.array([0.0, 0.0, GRAVITY]),
    )


def test_a_known_payload_on_a_static_stance_is_recovered() -> None:
    """+30 % of Cassie's mass 5.2 cm ahead of and 3.9 cm left of her centre of mass (the
    whole moved 1.2 and 0.9 cm), standing in her keyframe."""
    robot = load_robot("cassie")
    pinocchio = build_pinocchio_robot(robot)
    estimator = PayloadEstimator(robot, pinocchio, MPC_DT)
    q = pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
    model = pin.Model(pinocchio.model)  # the rider's model, the estimate put into it
    data = model.createData()
    com0 = np.array(pin.centerOfMass(model, data, q))
    mass0 = estimator.mass0
    extra = 0.3 * mass0
    at = com0 + np.array([0.052, 0.039, 0.0])  # the payload's place: 1.2, 0.9 cm shift
    true_com = (mass0 * com0 + extra * at) / (mass0 + extra)
    loads, torque = _stance_readings(estimator, len(robot.motors), q, mass0 + extra, true_com)
    imu = _standing_imu(q)
    contact = np.ones(len(loads), dtype=bool)
    estimate = PayloadEstimate(model_mass=mass0)
    for _ in range(600):  # 20 s of MPC steps: ten of the offset's time constants
        for _ in range(TICKS):
            estimator.accumulate(loads, contact, torque, imu)
        estimate = estimator.update(q, np.array(pin.centerOfMass(model, data, q)))
        for joint, inertia in enumerate(estimate.inertias(estimator.nominal_inertias)):
            model.inertias[joint] = inertia
    assert estimate.mass == pytest.approx(extra - MASS_DEADBAND * mass0, rel=1e-6)
    com = np.array(pin.centerOfMass(model, data, q))
    assert pin.computeTotalMass(model) == pytest.approx(mass0 + estimate.mass)
    assert np.linalg.norm(com[:2] - true_com[:2]) <= SHIFT_DEADBAND_M + 1e-4


SWAY_M = 0.01  # [m] sideways, the PD's start sway on the Hovershoes (1-3 cm across the feet)
SWAY_HZ = 1.7  # [Hz] the PD's sway under Cassie on the Hovershoes


def _swaying_estimate(
    open_loop: bool, seconds: float, settling: list[np.ndarray] | None = None
) -> tuple[PayloadEstimate, float, np.ndarray, np.ndarray]:
    """The estimate after ``seconds`` of a swaying stance with +20 % of Cassie's mass 4 cm
    ahead of and 4 cm right of her centre of mass (the whole moved 0.67 cm each way); its
    true mass beyond the model's [kg], the model's centre of mass's error [m] (world) and
    that error were the running mean put in whole (the base's frame is the world's here);
    ``settling`` collects what the takeover watches, MPC step by MPC step."""
    robot = load_robot("cassie")
    pinocchio = build_pinocchio_robot(robot)
    estimator = PayloadEstimator(robot, pinocchio, MPC_DT)
    q0 = pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
    model = pin.Model(pinocchio.model)
    data = model.createData()
    mass0 = estimator.mass0
    extra = 0.2 * mass0
    com0 = np.array(pin.centerOfMass(model, data, q0))
    true_shift = extra * np.array([0.04, -0.04, 0.0]) / (mass0 + extra)
    height = com0[2] - np.mean([p[2] for p in _site_points(estimator, q0)])
    omega = 2.0 * np.pi * SWAY_HZ
    imu, n_motors = _standing_imu(q0), len(robot.motors)
    estimate = PayloadEstimate(model_mass=mass0)
    v = np.zeros(model.nv)
    for k in range(round(seconds / MPC_DT)):
        t = (k + 1) * MPC_DT
        q = q0.copy()
        q[1] += SWAY_M * np.sin(omega * t)  # the whole rider sways sideways
        v[1] = SWAY_M * omega * np.cos(omega * t)
        sway_accel = -SWAY_M * omega**2 * np.sin(omega * t)
        true_com = np.array(pin.centerOfMass(estimator.model, estimator.data, q)) + true_shift
        pressure = true_com - np.array([0.0, height * sway_accel / GRAVITY, 0.0])
        loads, torque = _stance_readings(estimator, n_motors, q, mass0 + extra, pressure)
        for _ in range(TICKS):
            estimator.accumulate(loads, np.ones(len(loads), dtype=bool), torque, imu)
        com = np.array(pin.centerOfMass(model, data, q))
        estimate = estimator.update(q, com, v, open_loop=open_loop)
        if settling is not None:
            settling.append(estimate.settling())
        for joint, inertia in enumerate(estimate.inertias(estimator.nominal_inertias)):
            model.inertias[joint] = inertia
    error = np.array(pin.centerOfMass(model, data, q0)) - (com0 + true_shift)
    return estimate, extra, error, error + estimator.mean_shift - estimate.shift


def _site_points(estimator: PayloadEstimator, q: np.ndarray) -> list[np.ndarray]:
    pin.framesForwardKinematics(estimator.model, estimator.data, q)
    return [estimator.data.oMf[f].translation.copy() for foot in estimator.legs.feet
            for f in foot.sites]  # fmt: skip


def test_a_swaying_stance_on_the_backup_is_read_within_half_a_second() -> None:
    estimate, extra, error, mean_error = _swaying_estimate(open_loop=True, seconds=0.5)
    assert estimate.mass == pytest.approx(extra - MASS_DEADBAND * estimate.model_mass, abs=0.3)
    # [m] of a 0.94 cm offset; 5 mm without the sway's acceleration term
    assert np.linalg.norm(mean_error[:2]) <= 0.0025
    # into the models shortened by the mean's dead band
    assert np.linalg.norm(error[:2]) <= MEAN_DEADBAND_M + 0.0025
    _, _, slow_error, _ = _swaying_estimate(open_loop=False, seconds=0.5)
    assert np.linalg.norm(slow_error[:2]) >= 0.005  # the closed loop's 2 s integration


def test_the_takeover_finds_the_swaying_estimate_settled_once_it_is_right() -> None:
    """The running mean's steps shrink as 1/k: the takeover's rule (the pair's window and
    tolerances) finds it settled within a second, by when its offset is within 2.5 mm."""
    history: list[np.ndarray] = []
    _swaying_estimate(open_loop=True, seconds=1.5, settling=history)
    stage = load_pair_description("cassie", "hovershoes").stages.takeover
    readiness = start_readiness(stage, RETURN_DWELL_S)
    assert readiness is not None
    ready = [readiness.update(k * MPC_DT, e, True, False) for k, e in enumerate(history)]
    assert True in ready and ready.index(True) * MPC_DT <= 1.0
    seconds = (ready.index(True) + 1) * MPC_DT
    _, _, _, mean_error = _swaying_estimate(open_loop=True, seconds=seconds)
    assert np.linalg.norm(mean_error[:2]) <= 0.0025


def test_no_payload_reads_none() -> None:
    """The model's own weight under its centre of mass: no mass, no offset."""
    robot = load_robot("cassie")
    pinocchio = build_pinocchio_robot(robot)
    estimator = PayloadEstimator(robot, pinocchio, MPC_DT)
    q = pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
    com = np.array(pin.centerOfMass(estimator.model, estimator.data, q))
    loads, torque = _stance_readings(estimator, len(robot.motors), q, estimator.mass0, com)
    imu = _standing_imu(q)
    for _ in range(30):
        for _ in range(TICKS):
            estimator.accumulate(loads, np.ones(len(loads), dtype=bool), torque, imu)
        estimate = estimator.update(q, com)
    assert estimate.mass == 0.0
    np.testing.assert_allclose(estimate.shift, 0.0, atol=1e-9)


def test_a_negative_payload_is_a_lighter_rider() -> None:
    """-30 % of Cassie's mass on the base: every body 0.7 times as heavy, the centre of mass
    where it was."""
    robot = load_robot("cassie")
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, None)
    mass = -0.3 * robot.mass
    change = ParameterChange(parameter="payload", body="base", mass=mass)
    scenario = Scenario(name="lighter", duration=0.01, changes=(change,))
    sim = Simulation(scene, make_controller("stand", robot, "none"), scenario)
    model, data = scene.model, scene.data
    root = int(model.body_rootid[scene.base_body])
    scene.reset()
    mass0, com0 = float(model.body_subtreemass[root]), data.subtree_com[root].copy()
    try:
        sim.changes.apply(0, data)
        assert model.body_subtreemass[root] == pytest.approx(mass0 + mass)
        np.testing.assert_allclose(data.subtree_com[root], com0, atol=1e-12)
    finally:
        sim.changes.restore()
    assert model.body_subtreemass[root] == pytest.approx(mass0)
    with pytest.raises(ConfigError, match="takes off all of body 'base'"):
        heavy = ParameterChange(parameter="payload", body="base", mass=-1.5 * robot.mass)
        Simulation(scene, make_controller("stand", robot, "none"),
                   Scenario(name="none", duration=0.01, changes=(heavy,)))  # fmt: skip


def test_the_payload_stage_reads_the_running_mean_only_while_the_backup_rides() -> None:
    """The stage hands the estimator the last control tick's ``on_backup`` and the estimate's
    velocity (the sway's acceleration term)."""
    from types import SimpleNamespace

    from ridempc.mpc.stages.payload_models import PayloadModels

    calls: list[tuple[object, bool]] = []

    class _Estimator:
        estimate = SimpleNamespace(mass=0.0, inertias=lambda nominal: [])
        nominal_inertias: list[pin.Inertia] = []

        def accumulate(self, *args: object) -> None: ...

        def reset(self) -> None: ...

        def update(self, q: object, com: object, v: object, open_loop: bool) -> object:
            calls.append((v, open_loop))
            return self.estimate

    stage = PayloadModels(_Estimator(), [], lambda e: np.zeros(3), 8)  # type: ignore[arg-type]
    estimate = SimpleNamespace(q=np.zeros(7), v=np.ones(6), contact=np.ones(2, dtype=bool))
    sensors = SimpleNamespace(motor_torque=np.zeros(10), imu=None)
    mpc_tick = SimpleNamespace(estimate=estimate, balancing=True, diagnostics={})
    for on_backup in (True, False):
        control = SimpleNamespace(sensors=sensors, estimate=estimate, loads=np.ones(2),
                                  on_backup=on_backup)  # fmt: skip
        stage.observe(control)  # type: ignore[arg-type]
        stage.absorb(mpc_tick)  # type: ignore[arg-type]
    assert [open_loop for _, open_loop in calls] == [True, False]
    assert all(v is estimate.v for v, _ in calls)
