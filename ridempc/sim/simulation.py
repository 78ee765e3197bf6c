"""The multi-rate simulation loop.

Every physics step (``1 / physics_hz`` s), in this order:

1. disturbances and parameter changes due now are applied;
2. the VIO captures a sample if due (delivered later, after its latency);
3. the rider controller runs if due, on a fresh sensor packet and the scenario's command;
4. the board's firmware runs if due, on the board's own sensors;
5. the motor drivers apply their PD law to the latest motor command, within the torque-speed
   curve, through the torque delay line (:mod:`ridempc.sim.motors`);
6. MuJoCo steps.

Controllers run every ``physics_hz / rate_hz`` steps exactly (see :mod:`ridempc.sim.clock`).
The judge (fall detection, divergence checks, logging) reads the true state at
``log_hz``; nothing it reads reaches the controller. It also logs the controller's state
estimate (``Controller.estimate``), if it has one, next to the truth, to measure it.
Runs are deterministic for a seed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.controllers.base import Controller
from ridempc.errors import ConfigError, SimulationDiverged
from ridempc.heap import frozen_heap
from ridempc.rotations import yaw_of
from ridempc.scenarios.scenario import Disturbance, Scenario
from ridempc.sim.changes import ScheduledChanges
from ridempc.sim.clock import Rate
from ridempc.sim.falls import FallDetector
from ridempc.sim.motors import MotorDriver
from ridempc.sim.recorder import Recorder
from ridempc.sim.scene import BOARD_PREFIX, Scene
from ridempc.sim.sensors import SensorSuite

__all__ = ["RunResult", "Simulation"]

Array = NDArray[np.float64]
MAX_SPEED: float = 1000.0  # [m/s or rad/s] a generalised velocity above this is an explosion


@dataclass
class RunResult:
    """What happened in a run (from the judge's true-state view).

    Attributes:
        status: ``ok``, ``fell`` or ``failed``.
        sim_time: Simulated time reached [s].
        wall_time: Wall-clock time of the loop [s].
        fall_time: When the fall happened [s], or None.
        fall_reason: Why it counts as a fall, or None.
        error: Why the run failed, or None.
        log: Time series at the logging rate.
        controller_times: Wall time of each controller update [s].
        controller_cpu_times: CPU time of the loop's thread in each controller update [s]
            (``time.thread_time``: what a loaded machine's other processes do not add to,
            nor a wait for the MPC's solver thread or process).
        cpu_time: CPU time of the loop's thread over the loop [s].
    """

    status: str
    sim_time: float
    wall_time: float
    fall_time: float | None = None
    fall_reason: str | None = None
    error: str | None = None
    log: dict[str, Array] = field(default_factory=dict)
    controller_times: Array = field(default_factory=lambda: np.zeros(0))
    controller_cpu_times: Array = field(default_factory=lambda: np.zeros(0))
    cpu_time: float = 0.0

    @property
    def fell(self) -> bool:
        return self.fall_time is not None


class Simulation:
    """Runs one scenario with one controller on one scene.

    Args:
        scene: The compiled scene (reset to its initial state here).
        controller: The rider controller (None when a dead weight rides).
        scenario: Duration, commands, disturbances, noise and changes.
        seed: Seed of every random draw in the run (sensor noise).
        ground_truth: Put ground truth in the sensor packets (debugging only).
        log_hz: Logging and judging rate [Hz].
        frame_hz: Rate of ``on_frame`` calls [Hz] (video).
        on_frame: Called with (model, data) at ``frame_hz``, e.g. to render video.
        external: Called with (t, model, data) at every physics step after the scenario's
            disturbances are set, to add scripted external forces to ``data.xfrc_applied``
            (identification experiments).
    """

    def __init__(
        self,
        scene: Scene,
        controller: Controller | None,
        scenario: Scenario,
        seed: int = 0,
        ground_truth: bool = False,
        log_hz: float = 100.0,
        frame_hz: float = 30.0,
        on_frame: Callable[[mujoco.MjModel, mujoco.MjData], None] | None = None,
        external: Callable[[float, mujoco.MjModel, mujoco.MjData], None] | None = None,
    ) -> None:
        self.external = external
        self.scene = scene
        self.controller = controller
        self.scenario = scenario
        self.seed = seed
        hz = scene.physics_hz
        self.log_rate = Rate.of(log_hz, hz, "log")
        self.frame_rate = Rate.of(frame_hz, hz, "video frame")
        self.on_frame = on_frame
        self.ground_truth = ground_truth
        robot = scene.robot
        if (robot is None) != (controller is None):
            raise ConfigError("a robot needs a controller, and a dead weight takes none")
        self.sensors: SensorSuite | None = None
        self.driver: MotorDriver | None = None
        if robot is not None and controller is not None:
            self.control_rate = Rate.of(controller.rate_hz, hz, "controller")
            controller.command_preview = scenario.command_at  # the planned command timeline
            self.sensors = SensorSuite(
                scene.model,
                encoder_joints=robot.encoder_joints,
                base_body=robot.params.base_body,
                imu_site=robot.params.imu_site,
                robot_qpos=scene.robot_qpos,
                robot_qvel=scene.robot_qvel,
                actuators=scene.actuator_ids,
                noise=scenario.noise,
                physics_hz=hz,
                rng=np.random.default_rng(seed),
                ground_truth=ground_truth,
            )
            self.driver = MotorDriver(scene.model, robot.motors, scene.actuator_ids)
        self.firmware: Firmware | None = None
        if scene.board is not None:
            io = BoardIO(scene.model, BOARD_PREFIX)
            io.bind(scene.data)
            self.firmware = scene.board.firmware(io)
            self.firmware_rate = Rate.of(self.firmware.rate_hz, hz, "board firmware")
        self.falls = FallDetector(scene, feet_on_ground=scenario.push_off is not None)
        # a controller with an estimator gets its estimate logged next to the truth
        self._logs_estimate = (
            controller is not None and type(controller).estimate is not Controller.estimate
        )
        self._pushes = [(self._body_of(d), d) for d in scenario.disturbances]
        self.changes = ScheduledChanges(
            scene, scenario.changes, self.firmware, self.driver, f"scenario '{scenario.name}'"
        )

    def _body_of(self, disturbance: Disturbance) -> int:
        if disturbance.body == "base":
            return self.scene.base_body
        body = mujoco.mj_name2id(self.scene.model, mujoco.mjtObj.mjOBJ_BODY, disturbance.body)
        if body < 0:
            names = [
                mujoco.mj_id2name(self.scene.model, mujoco.mjtObj.mjOBJ_BODY, b)
                for b in range(1, self.scene.model.nbody)
            ]
            raise ConfigError(
                f"scenario '{self.scenario.name}': disturbance body '{disturbance.body}' "
                f"does not exist (valid: base, {', '.join(names)})"
            )
        return body

    def _apply_disturbances(self, t: float, data: mujoco.MjData) -> None:
        data.xfrc_applied[:] = 0.0
        mass = self.scene.rider_mass
        for body, push in self._pushes:
            if push.t <= t < push.t + push.duration:
                scale = mass if push.per_kg else 1.0
                data.xfrc_applied[body, :3] += scale * np.asarray(push.force)
                data.xfrc_applied[body, 3:] += scale * np.asarray(push.torque)

    def _log_row(self, recorder: Recorder, t: float, data: mujoco.MjData) -> None:
        scene = self.scene
        base = scene.base_body
        velocity = np.empty(6)
        mujoco.mj_objectVelocity(scene.model, data, mujoco.mjtObj.mjOBJ_BODY, base, velocity, 0)
        yaw = yaw_of(data.xquat[base])
        command = self.scenario.command_at(t)
        recorder.append(
            time=t,
            base_position=data.xpos[base],
            base_quaternion=data.xquat[base],
            base_velocity=velocity[3:],
            base_angular_velocity=velocity[:3],
            forward_velocity=np.cos(yaw) * velocity[3] + np.sin(yaw) * velocity[4],
            yaw=yaw,
            yaw_rate=velocity[2],
            command_velocity=command.velocity,
            command_yaw_rate=command.yaw_rate,
            command_roll=command.roll,
            command_lateral_offset=command.lateral_offset,
        )
        if self.driver is not None:
            recorder.append(
                qpos=data.qpos[scene.robot_qpos],
                qvel=data.qvel[scene.robot_qvel],
                motor_torque=self.driver.torque(data),
                motor_demand=self.driver.demand,
                motor_available=self.driver.available,
            )
        if scene.board_roots:
            board_velocity = np.empty((len(scene.board_roots), 6))
            for i, body in enumerate(scene.board_roots):
                mujoco.mj_objectVelocity(
                    scene.model, data, mujoco.mjtObj.mjOBJ_BODY, body, board_velocity[i], 0
                )
            roots = list(scene.board_roots)
            recorder.append(
                board_position=data.xpos[roots],
                board_quaternion=data.xquat[roots],
                board_velocity=board_velocity[:, 3:],
                board_angular_velocity=board_velocity[:, :3],
            )
        if self.firmware is not None:
            recorder.append(**{f"firmware_{k}": v for k, v in self.firmware.diagnostics().items()})
        if self._logs_estimate:
            self._log_estimate(recorder)

    def _log_estimate(self, recorder: Recorder) -> None:
        """The controller's latest estimate (from its last tick, before this row), or NaN."""
        assert self.controller is not None
        estimate = self.controller.estimate()
        if estimate is None:
            nan3 = np.full(3, np.nan)
            recorder.append(
                estimate_time=np.nan,
                estimate_base_position=nan3,
                estimate_base_velocity=nan3,
                estimate_yaw=np.nan,
            )
            return
        recorder.append(
            estimate_time=estimate.time,
            estimate_base_position=estimate.base_position,
            estimate_base_velocity=estimate.base_velocity,
            estimate_yaw=estimate.yaw,
        )

    def _check_finite(self, t: float, data: mujoco.MjData) -> None:
        bad_acc = data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number
        if bad_acc:
            raise SimulationDiverged(t, "MuJoCo reported a bad acceleration (NaN or Inf)")
        if not np.isfinite(data.qpos).all() or not np.isfinite(data.qvel).all():
            raise SimulationDiverged(t, "state is not finite")
        speed = float(np.abs(data.qvel).max())
        if speed > MAX_SPEED:
            raise SimulationDiverged(t, f"a velocity reached {speed:.3g} (limit {MAX_SPEED})")

    def _control(self, tick: int, t: float, data: mujoco.MjData) -> tuple[float, float]:
        """One controller tick; returns its wall time and its thread's CPU time [s]."""
        assert self.sensors is not None and self.driver is not None and self.controller
        packet = self.sensors.read(tick, data)
        if tick == 0:
            self.controller.reset(packet)
        began, began_cpu = time.perf_counter(), time.thread_time()
        command = self.controller.update(packet, self.scenario.command_at(t))
        elapsed = time.perf_counter() - began, time.thread_time() - began_cpu
        if not command.is_finite():
            raise SimulationDiverged(t, "the controller returned a non-finite command")
        self.driver.command = command
        return elapsed

    def run(self) -> RunResult:
        """Run the scenario to its end, a fall or a failure."""
        scene = self.scene
        model, data = scene.model, scene.data
        scene.reset()
        if self.driver is not None:
            self.driver.reset()
        hz = scene.physics_hz
        n_ticks = round(self.scenario.duration * hz)
        recorder = Recorder()
        times: list[tuple[float, float]] = []  # each controller update's wall and CPU time
        result = RunResult(status="ok", sim_time=0.0, wall_time=0.0)
        tick = 0
        with frozen_heap():  # the models and the library stay out of the collector's walks
            start, start_cpu = time.perf_counter(), time.thread_time()
            try:
                self.changes.apply(0, data)  # before the first step: a heavier rider starts so
                for tick in range(n_ticks + 1):
                    t = tick / hz
                    if self.log_rate.due(tick):
                        self._check_finite(t, data)
                        self._log_row(recorder, t, data)
                        reason = self.falls.check(model, data)
                        if reason is not None:
                            result.status, result.fall_time, result.fall_reason = "fell", t, reason
                            break
                    if self.on_frame is not None and self.frame_rate.due(tick):
                        self.on_frame(model, data)
                    if tick == n_ticks:
                        break
                    if tick:
                        self.changes.apply(tick, data)
                    self._apply_disturbances(t, data)
                    if self.external is not None:
                        self.external(t, model, data)
                    if self.sensors is not None and self.driver is not None:
                        self.sensors.sample_vio(tick, data)
                        if self.control_rate.due(tick):
                            times.append(self._control(tick, t, data))
                        self.driver.apply(data)
                    if self.firmware is not None and self.firmware_rate.due(tick):
                        self.firmware.update()
                    mujoco.mj_step(model, data)
            except SimulationDiverged as exc:
                result.status, result.error = "failed", str(exc)
            finally:  # parameter changes last one run only
                self.changes.restore()
                if self.controller is not None:
                    self.controller.close()
        result.sim_time = tick / hz
        result.wall_time = time.perf_counter() - start
        result.cpu_time = time.thread_time() - start_cpu
        result.log = recorder.arrays()
        spent = np.array(times).reshape(-1, 2)
        result.controller_times = spent[:, 0].copy()
        result.controller_cpu_times = spent[:, 1].copy()
        return result
