"""What a rider controller receives: IMU, joint encoders, motor torques and visual odometry.

A controller never reads the simulator's state. Each control tick it gets one
:class:`SensorPacket`, built here from MuJoCo's sensors and the true state with the noise,
quantisation and latency of :class:`SensorNoise`:

- IMU at the robot's IMU site: orientation quaternion (w, x, y, z) with a small random
  tilt/yaw error, gyro :math:`\\omega_B + n_\\omega` [rad/s] and accelerometer
  :math:`R_{WB}^\\top(\\ddot p - g) + n_a` [m/s^2] (MuJoCo's ``accelerometer``).
- Joint encoders: position quantised to the encoder resolution plus noise [rad], velocity
  plus noise [rad/s], for the motor joints and the instrumented passive joints.
- Motor torques: the joint-side torque each motor applied [N m].
- Visual-inertial odometry (VIO): base position [m], yaw [rad], world-frame velocity [m/s]
  and yaw rate [rad/s], sampled at ``vio_hz`` and delivered ``vio_latency`` seconds later,
  each with Gaussian noise. ``vio`` is the newest delivered sample (or None before the first),
  stamped with the time it was captured.

Ground truth (``truth``) is filled only when the simulation runs with ``ground_truth=True``,
for debugging; a run that feeds it back is marked as such in its summary.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Annotated

import mujoco
import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from ridempc.rotations import yaw_of
from ridempc.units import CheckedModel, Real

__all__ = ["GroundTruth", "ImuReading", "SensorNoise", "SensorPacket", "SensorSuite", "VioReading"]

Array = NDArray[np.float64]


# Upper bounds of the noise figures: at them a reading says nothing (a 0.5 rad tilt, a 1 m
# position error), so a larger figure is a slip of units (degrees for radians), not a sensor.
_Std = Annotated[Real, Field(ge=0.0)]


class SensorNoise(CheckedModel):
    """Noise, resolution and latency of the rider's sensors (scenario ``[noise]`` table)."""

    imu_orientation_std: Annotated[_Std, Field(le=0.5)] = Field(0.002, description="[rad] per axis")
    imu_gyro_std: Annotated[_Std, Field(le=5.0)] = Field(0.005, description="[rad/s]")
    imu_accel_std: Annotated[_Std, Field(le=50.0)] = Field(0.05, description="[m/s^2]")
    encoder_resolution: Annotated[_Std, Field(le=0.5)] = Field(
        2 * np.pi / 2**14, description="[rad] quantisation step (14-bit)"
    )
    encoder_velocity_std: Annotated[_Std, Field(le=5.0)] = Field(0.01, description="[rad/s]")
    torque_std: Annotated[_Std, Field(le=50.0)] = Field(0.05, description="[N m]")
    # A camera-IMU odometry runs at most at a camera's 1 kHz.
    vio_hz: Annotated[Real, Field(gt=0.0, le=1000.0)] = Field(30.0, description="[Hz]")
    vio_latency: Annotated[_Std, Field(le=1.0)] = Field(
        0.03, description="[s] capture-to-delivery delay"
    )
    vio_position_std: Annotated[_Std, Field(le=1.0)] = Field(0.01, description="[m]")
    vio_yaw_std: Annotated[_Std, Field(le=0.5)] = Field(0.005, description="[rad]")
    vio_velocity_std: Annotated[_Std, Field(le=5.0)] = Field(0.02, description="[m/s]")
    vio_yaw_rate_std: Annotated[_Std, Field(le=5.0)] = Field(0.01, description="[rad/s]")


@dataclass(frozen=True)
class ImuReading:
    quaternion: Array  # (w, x, y, z), body to world
    angular_velocity: Array  # [rad/s], body frame
    linear_acceleration: Array  # [m/s^2], body frame, specific force


@dataclass(frozen=True)
class VioReading:
    stamp: float  # [s] capture time
    position: Array  # [m], world
    yaw: float  # [rad]
    velocity: Array  # [m/s], world
    yaw_rate: float  # [rad/s]


@dataclass(frozen=True)
class GroundTruth:
    qpos: Array  # robot's MuJoCo configuration
    qvel: Array  # robot's MuJoCo velocity


@dataclass(frozen=True)
class SensorPacket:
    """Everything a rider controller may read at one control tick.

    Attributes:
        time: Simulation time [s].
        imu: The IMU reading.
        joint_position: Encoder positions [rad], ordered as ``SensorSuite.encoder_joints``.
        joint_velocity: Encoder velocities [rad/s], same order.
        motor_torque: Joint-side torque applied by each motor [N m], actuator order.
        vio: Newest delivered VIO sample, or None before the first arrives.
        truth: Ground truth, only when the run enables it for debugging.
    """

    time: float
    imu: ImuReading
    joint_position: Array
    joint_velocity: Array
    motor_torque: Array
    vio: VioReading | None
    truth: GroundTruth | None = None


class SensorSuite:
    """Reads MuJoCo sensors and the true base state into noisy, delayed sensor packets.

    Args:
        model: Compiled scene holding the robot's sensors (added by the scene builder).
        encoder_joints: Joints with encoders, in packet order.
        base_body: Name of the robot's base body (VIO is attached to it).
        imu_site: Name of the IMU site.
        robot_qpos: Slice of the scene's qpos that is the robot's.
        robot_qvel: Slice of the scene's qvel that is the robot's.
        actuators: Scene actuator ids of the robot's motors.
        noise: Noise, resolution and latency.
        physics_hz: Physics rate [Hz], to express the VIO latency in steps.
        rng: Random generator (seeded by the run).
        ground_truth: Fill ``SensorPacket.truth`` (debugging only).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        encoder_joints: tuple[str, ...],
        base_body: str,
        imu_site: str,
        robot_qpos: slice,
        robot_qvel: slice,
        actuators: NDArray[np.int64],
        noise: SensorNoise,
        physics_hz: int,
        rng: np.random.Generator,
        ground_truth: bool = False,
    ) -> None:
        self._model = model
        self.noise = noise
        self.rng = rng
        self.ground_truth = ground_truth
        self.encoder_joints = encoder_joints
        joint_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in encoder_joints]
        self._enc_qpos = np.array([model.jnt_qposadr[j] for j in joint_ids])
        self._enc_dof = np.array([model.jnt_dofadr[j] for j in joint_ids])
        self._base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, base_body)
        self._robot_qpos = robot_qpos
        self._robot_qvel = robot_qvel
        self._actuators = actuators
        # MuJoCo's actuator_force is on the motor side of the gear; the packet holds joint side
        self._gear = np.array(model.actuator_gear[actuators, 0])
        self._imu_quat = self._sensor_slice(model, f"{imu_site}_quat")
        self._imu_gyro = self._sensor_slice(model, f"{imu_site}_gyro")
        self._imu_acc = self._sensor_slice(model, f"{imu_site}_accel")
        self._vio_period = max(1, round(physics_hz / noise.vio_hz))
        self._vio_delay = round(noise.vio_latency * physics_hz)
        self._physics_hz = physics_hz
        self._vio_queue: deque[tuple[int, VioReading]] = deque()
        self._vio_latest: VioReading | None = None
        # A packet's noise in one draw: per entry its std, in the order of the draws of one
        # reading at a time, so a seed gives the same noise (normal(0, s) is s times a
        # standard normal; normal() with an array of stds costs 12 us, this 3). A reading
        # with zero std takes no draw and gets zeros.
        count, motors = len(joint_ids), len(actuators)
        stds = (
            (noise.imu_orientation_std, 3),
            (noise.imu_gyro_std, 3),
            (noise.imu_accel_std, 3),
            (noise.encoder_velocity_std, count),
            (noise.torque_std, motors),
        )
        self._packet_size = sum(size for _, size in stds)
        packet_std = np.repeat([std for std, _ in stds], [size for _, size in stds])
        self._packet_noisy = np.flatnonzero(packet_std > 0)
        self._packet_std = packet_std[self._packet_noisy]
        ends = np.cumsum([size for _, size in stds])
        self._tilt, self._gyro, self._accel, self._encoder_rate, self._torque = (
            slice(end - size, end) for end, (_, size) in zip(ends, stds, strict=True)
        )

    @staticmethod
    def _sensor_slice(model: mujoco.MjModel, name: str) -> slice:
        sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
        adr, dim = int(model.sensor_adr[sid]), int(model.sensor_dim[sid])
        return slice(adr, adr + dim)

    def _noise(self, std: float, size: int) -> Array:
        return self.rng.normal(0.0, std, size) if std > 0 else np.zeros(size)

    def sample_vio(self, tick: int, data: mujoco.MjData) -> None:
        """At VIO rate: capture the base pose now, to be delivered after the latency."""
        if tick % self._vio_period:
            return
        n = self.noise
        quat = data.xquat[self._base]
        vel_world = self._base_velocity_world(data)
        reading = VioReading(
            stamp=tick / self._physics_hz,
            position=data.xpos[self._base] + self._noise(n.vio_position_std, 3),
            yaw=yaw_of(quat) + float(self._noise(n.vio_yaw_std, 1)[0]),
            velocity=vel_world[3:] + self._noise(n.vio_velocity_std, 3),
            yaw_rate=float(vel_world[2]) + float(self._noise(n.vio_yaw_rate_std, 1)[0]),
        )
        self._vio_queue.append((tick + self._vio_delay, reading))

    def _base_velocity_world(self, data: mujoco.MjData) -> Array:
        """(angular, linear) velocity of the base origin in the world frame."""
        out = np.empty(6)
        mujoco.mj_objectVelocity(self._model, data, mujoco.mjtObj.mjOBJ_BODY, self._base, out, 0)
        return out

    def read(self, tick: int, data: mujoco.MjData) -> SensorPacket:
        """The packet a controller gets at this tick (after ``mj_forward``/``mj_step``)."""
        n = self.noise
        while self._vio_queue and self._vio_queue[0][0] <= tick:
            self._vio_latest = self._vio_queue.popleft()[1]
        noise = np.zeros(self._packet_size)
        noise[self._packet_noisy] = self._packet_std * self.rng.standard_normal(
            self._packet_std.size
        )
        quat = np.array(data.sensordata[self._imu_quat])
        tilt = noise[self._tilt]
        if tilt.any():  # the method: np.any's wrapper costs 3 us
            angle = math.sqrt(tilt @ tilt)  # np.linalg.norm's sum, without its wrapper
            error = np.empty(4)
            mujoco.mju_axisAngle2Quat(error, tilt / angle, angle)
            mujoco.mju_mulQuat(quat, quat.copy(), error)
        imu = ImuReading(
            quaternion=quat,
            angular_velocity=data.sensordata[self._imu_gyro] + noise[self._gyro],
            linear_acceleration=data.sensordata[self._imu_acc] + noise[self._accel],
        )
        q = data.qpos[self._enc_qpos]
        if n.encoder_resolution > 0:
            q = np.rint(q / n.encoder_resolution) * n.encoder_resolution  # np.round's
        truth = None
        if self.ground_truth:
            truth = GroundTruth(
                qpos=np.array(data.qpos[self._robot_qpos]),
                qvel=np.array(data.qvel[self._robot_qvel]),
            )
        return SensorPacket(
            time=tick / self._physics_hz,
            imu=imu,
            joint_position=q,
            joint_velocity=data.qvel[self._enc_dof] + noise[self._encoder_rate],
            motor_torque=self._gear * data.actuator_force[self._actuators] + noise[self._torque],
            vio=self._vio_latest,
            truth=truth,
        )
