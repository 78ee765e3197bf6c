"""Cassie's quiet-standing controller (Segway paper, section IV-A): the ``pd`` baseline.

The controller reads only the sensor packet (IMU orientation and rate, encoders; never
``truth``) and works in the virtual-leg coordinates (leg length :math:`L`, relative leg angle
:math:`\\theta`) of :mod:`ridempc.baselines.cassie_kinematics`. Per tick, for targets
:class:`StandingTargets` (starred):

1. **Roll by the leg-length difference.** With the pelvis roll :math:`\\phi` from the IMU
   (low-pass filtered, ``roll.filter_hz``),

   .. math:: L_{L,R}^* = \\bar L^* \\mp u, \\qquad
       u = k_p^\\phi (\\phi - \\phi^*) + k_d^\\phi \\dot\\phi
           + k_i^\\phi \\textstyle\\int (\\phi - \\phi^*)\\,dt

   [m]: when the pelvis rolls left side up (:math:`\\phi > 0`) the left leg shortens and the
   right one extends; on sloped ground the legs take different lengths by themselves.
2. **Height by the mean leg length** :math:`\\bar L^*`, a posture setpoint followed at most at
   ``legs.max_speed`` (crouching and standing up).
3. **Pelvis pitch by the leg angle.** The absolute leg angle is :math:`\\theta - \\beta`
   (pelvis pitch :math:`\\beta` from the IMU, positive nose down), so an upright pelvis needs
   :math:`\\theta_i^* = \\theta_i - (\\beta - \\beta^*)`: the hip-pitch stiffness acts on the
   pelvis pitch error, its damping on the joint rate.
4. **Joint targets by inverse kinematics** :math:`(L_i^*, \\theta_i^*) \\mapsto
   (q_{hp}, q_{knee})` on the rigid leg (springs at rest, tarsus on the knee by eq. 3), with
   the knee's velocity target :math:`\\dot L_i^* / (\\partial L / \\partial q_{knee})`,
   :math:`\\dot L_i^* = \\mp k_p^\\phi \\dot\\phi`. Hip roll and hip yaw are held at the
   posture; the hip roll leans both legs by :math:`-\\arctan(y^*/\\bar L)` to shift the pelvis
   :math:`y^*` sideways over the feet (zero when standing; for riders).
5. **CoM x by toe pitch.** From the centre of mass :math:`x` relative to the feet's support
   centre and its velocity :math:`\\dot x` (kinematics from the encoders and the IMU
   orientation, feet at rest; low-pass filtered, ``com_x.filter_hz``), the centre of
   pressure

   .. math:: p_x^* = x + k_p^x (x - x^*) + k_d^x \\dot x

   clamped to each foot's contact line, stabilises the linear inverted pendulum
   :math:`\\ddot x = \\frac{g}{z}(x - p_x)`: :math:`\\ddot x = -\\frac{g}{z}
   (k_p^x (x - x^*) + k_d^x \\dot x)` while the CoP is inside the feet. In capture-point
   terms, :math:`k_p^x = k_\\xi` and :math:`k_d^x = (1 + k_\\xi)/\\omega`,
   :math:`\\omega = \\sqrt{g/z}`.
6. **Feedforward** by inverse statics (:mod:`ridempc.baselines.cassie_statics`): the ground
   forces :math:`f_i = (w_i F_x, 0, w_i m g)` at the feet's centres of pressure, with the
   weight shares :math:`w_i` that put the vertical forces' centre under the CoM laterally
   and :math:`F_x = m g (x - p_x)/z`, give every motor's torque: gravity compensation for
   hips and knees, and the toe torques that place the centre of pressure.

Each motor then runs :math:`\\tau = \\tau_{ff} + k_p (q^* - q) + k_d (\\dot q^* - \\dot q)`
at the physics rate; the toe's target is its measured angle, so with ``toe.kp = 0`` the toe
is torque-driven and damped. Gains: ``cassie_standing.toml``.

Riders (Segway, Hovershoes) build on it by overriding :meth:`CassieStanding.targets`
(the CoM target in x to accelerate, the sideways shift to lean, a lower leg length to crouch)
and adding torques to the returned command.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ridempc.baselines.cassie_kinematics import (
    SIDES,
    CassieKinematics,
    KinematicState,
    LegIndices,
    VirtualLeg,
)
from ridempc.baselines.cassie_standing_gains import (
    DEFAULT_GAINS_FILE,
    CassieStandingGains,
    load_standing_gains,
)
from ridempc.baselines.cassie_statics import FootLoad, StandingStatics
from ridempc.baselines.filters import LowPassFilter
from ridempc.boards import support_height
from ridempc.controllers.base import Controller
from ridempc.estimation import EstimatedState, StateEstimator
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = ["CassieStanding", "StandingTargets"]

Array = NDArray[np.float64]
SIGN: dict[str, float] = {"left": 1.0, "right": -1.0}  # mirrored joints: hip roll and yaw


@dataclass(frozen=True)
class StandingTargets:
    """What the standing controller regulates; riders change these in
    :meth:`CassieStanding.targets` (``dataclasses.replace`` on the nominal ones).

    Attributes:
        com_x: CoM x relative to the feet's support centre, heading frame [m].
        com_y: Sideways shift of the pelvis over the feet, made by leaning both legs
            with the hip roll [m] (+ to the left).
        leg_length: Mean virtual leg length [m].
        roll: Pelvis roll [rad], positive with the left side up.
        pitch: Pelvis pitch [rad], positive nose down.
        hip_roll: Outward hip roll of each leg [rad] (left joint +, right joint -).
        hip_yaw: Hip yaw of each leg [rad] (left joint +, right joint -: mirrored).
    """

    com_x: float
    com_y: float
    leg_length: float
    roll: float
    pitch: float
    hip_roll: float
    hip_yaw: float


class CassieStanding(Controller):
    """Quiet standing: CoM x by toe pitch, roll by leg-length difference, height by the mean
    leg length, pelvis pitch by the leg angle, hip roll and yaw held.

    Args:
        robot: Cassie.
        board: The board's name (``none`` on flat ground); standing ignores it.
        gains: Checked gains, or the gain file to read (``cassie_standing.toml``).
        platforms: The feet on each board platform, for the state estimator (default: both
            feet on one platform on a board, none on flat ground).

    Raises:
        ConfigError: The gain file is malformed, or the robot lacks Cassie's joints.
    """

    def __init__(
        self,
        robot: Robot,
        board: str = "none",
        gains: CassieStandingGains | Path | str = DEFAULT_GAINS_FILE,
        platforms: tuple[tuple[str, ...], ...] | None = None,
    ) -> None:
        super().__init__(robot, board)
        if platforms is None:
            platforms = (robot.params.foot_bodies,) if board != "none" else ()
        # Runs on every tick, so every ride reports the estimator's error; the riders on a
        # board read its state, standing reads only the IMU and the encoders.
        self.estimator = StateEstimator(
            robot, platforms=platforms, support_height=support_height(board)
        )
        self.gains = gains if isinstance(gains, CassieStandingGains) else load_standing_gains(gains)
        self.rate_hz = self.gains.rate_hz
        self.kinematics = CassieKinematics(robot)
        self.statics = StandingStatics(self.kinematics)
        self.legs: dict[str, VirtualLeg] = {s: self.kinematics.virtual_leg(s) for s in SIDES}
        self.n_motors = len(robot.motors)
        joints = self.gains.joints
        per_joint = (joints.hip_roll, joints.hip_yaw, joints.hip_pitch, joints.knee, joints.toe)
        self._kp = np.zeros(self.n_motors)
        self._kd = np.zeros(self.n_motors)
        for side in SIDES:
            for k, motor in enumerate(self.kinematics.legs[side].motors):
                self._kp[motor] = per_joint[k].kp
                self._kd[motor] = per_joint[k].kd
        self._nominal: StandingTargets | None = None
        self._roll_integral = 0.0
        self._last_time: float | None = None
        self._com_filter = LowPassFilter(self.gains.com_x.filter_hz)
        self._roll_filter = LowPassFilter(self.gains.roll.filter_hz)
        self._roll_rate = 0.0
        self._leg_length: float | None = None
        self._leg_length_time = 0.0
        self._diagnostics: dict[str, float] = {}

    # ------------------------------------------------------------------ state

    def kinematic_state(self, sensors: SensorPacket) -> KinematicState:
        """The kinematic state from the packet's IMU and encoders (never ground truth)."""
        return self.kinematics.measure(
            sensors.time,
            sensors.imu.quaternion,
            sensors.imu.angular_velocity,
            sensors.joint_position,
            sensors.joint_velocity,
        )

    def reset(self, sensors: SensorPacket) -> None:
        """Take the posture fields the gain file leaves out from the first packet."""
        state = self.kinematic_state(sensors)
        posture = self.gains.posture
        lengths = []
        rolls = []
        yaws = []
        for side in SIDES:
            leg = self.kinematics.legs[side]
            q = state.motor_position
            hip_pitch = q[leg.motors[LegIndices.HIP_PITCH]]
            knee = q[leg.motors[LegIndices.KNEE]]
            lengths.append(self.legs[side].forward(hip_pitch, knee)[0])
            rolls.append(SIGN[side] * q[leg.motors[LegIndices.HIP_ROLL]])
            yaws.append(SIGN[side] * q[leg.motors[LegIndices.HIP_YAW]])
        self._nominal = StandingTargets(
            com_x=self.gains.com_x.target,
            com_y=0.0,
            leg_length=posture.leg_length or float(np.mean(lengths)),
            roll=0.0,
            pitch=posture.pitch,
            hip_roll=posture.hip_roll if posture.hip_roll is not None else float(np.mean(rolls)),
            hip_yaw=posture.hip_yaw if posture.hip_yaw is not None else float(np.mean(yaws)),
        )
        self._roll_integral = 0.0
        self._last_time = None
        self._com_filter.reset()
        self._roll_filter.reset()
        self._leg_length = None
        self.estimator.reset(sensors)

    @property
    def nominal(self) -> StandingTargets:
        """The standing targets (set by the first packet)."""
        if self._nominal is None:
            raise RuntimeError("CassieStanding.nominal is set by the first sensor packet")
        return self._nominal

    def targets(self, state: KinematicState, command: Command) -> StandingTargets:
        """The standing targets: the posture, whatever the command (riders override)."""
        return self.nominal

    # ------------------------------------------------------------------ law

    def _roll_feedback(self, state: KinematicState, target: float) -> float:
        """:math:`u = k_p (\\phi - \\phi^*) + k_d \\dot\\phi + k_i \\int (\\phi - \\phi^*)` [m]."""
        gains = self.gains.roll
        roll, rate = self._roll_filter(
            state.time, np.array([state.roll, state.angular_velocity[0]])
        )
        error = roll - target
        dt = 0.0 if self._last_time is None else state.time - self._last_time
        self._last_time = state.time
        if gains.ki > 0.0:
            bound = gains.integral_limit / gains.ki
            self._roll_integral = min(max(self._roll_integral + error * dt, -bound), bound)
        self._roll_rate = float(rate)
        return gains.kp * error + gains.kd * rate + gains.ki * self._roll_integral

    def _slew_leg_length(self, time: float, target: float) -> float:
        """The mean leg length moved towards ``target`` at most at ``legs.max_speed`` [m]."""
        if self._leg_length is None:
            self._leg_length = target
        step = self.gains.legs.max_speed * max(time - self._leg_length_time, 0.0)
        self._leg_length += min(max(target - self._leg_length, -step), step)
        self._leg_length_time = time
        return self._leg_length

    def foot_loads(self, state: KinematicState, targets: StandingTargets) -> dict[str, FootLoad]:
        """Ground forces for the CoP law (step 5) and the feedforward (step 6), world axes."""
        gains = self.gains.com_x
        x, dx = self._com_filter(state.time, np.array([state.com_offset[0], state.com_velocity[0]]))
        cop = state.support_centre[0] + x + gains.kp * (x - targets.com_x) + gains.kd * dx
        contacts = state.contacts
        y_feet = [contacts[0:2, 1].mean(), contacts[2:4, 1].mean()]
        share_left = min(max((state.com[1] - y_feet[1]) / (y_feet[0] - y_feet[1]), 0.0), 1.0)
        shares = (share_left, 1.0 - share_left)
        weight = self.kinematics.mass * self.kinematics.gravity
        points = []
        for i in range(2):
            front, back = contacts[2 * i], contacts[2 * i + 1]
            low = min(front[0], back[0]) + gains.cop_margin
            high = max(front[0], back[0]) - gains.cop_margin
            along = (min(max(cop, low), high) - back[0]) / (front[0] - back[0])
            points.append(back + along * (front - back))
        achieved = shares[0] * points[0][0] + shares[1] * points[1][0]
        height = max(state.com[2] - state.support_centre[2], 0.3)
        push = weight * (state.support_centre[0] + x - achieved) / height
        c, s = np.cos(state.yaw), np.sin(state.yaw)
        to_world = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        self._diagnostics.update(cop_x=float(achieved - state.support_centre[0]), com_x=float(x))
        return {
            side: FootLoad(
                point=to_world @ points[i],
                force=to_world @ np.array([shares[i] * push, 0.0, shares[i] * weight]),
            )
            for i, side in enumerate(SIDES)
        }

    def leg_extension(self, side: str) -> float:
        """A leg's length added to the posture's [m]; none here."""
        return 0.0

    def motor_command(self, state: KinematicState, targets: StandingTargets) -> MotorCommand:
        """Steps 1-6: joint targets, their velocities and the feedforward torques."""
        position = state.motor_position.copy()  # the toe's target: where it is
        velocity = np.zeros(self.n_motors)
        u = self._roll_feedback(state, targets.roll)
        d_u = self.gains.roll.kp * self._roll_rate
        limits = self.gains.legs
        mean_length = self._slew_leg_length(state.time, targets.leg_length)
        lean = -np.arctan2(targets.com_y, mean_length)
        for side in SIDES:
            m, table, sign = self.kinematics.legs[side].motors, self.legs[side], SIGN[side]
            length = mean_length - sign * u + self.leg_extension(side)
            length = min(max(length, limits.min_length), limits.max_length)
            measured = table.forward(
                state.motor_position[m[LegIndices.HIP_PITCH]],
                state.motor_position[m[LegIndices.KNEE]],
            )
            angle = measured[1] - (state.pitch - targets.pitch)
            hip_pitch, knee = table.inverse(length, angle)
            position[m[LegIndices.HIP_ROLL]] = sign * targets.hip_roll + lean
            position[m[LegIndices.HIP_YAW]] = sign * targets.hip_yaw
            position[m[LegIndices.HIP_PITCH]] = hip_pitch
            position[m[LegIndices.KNEE]] = knee
            velocity[m[LegIndices.KNEE]] = -sign * d_u / table.jacobian(knee)[0, 1]
            self._diagnostics[f"{side}_leg_length_target"] = length
        torque = self.statics.motor_torques(state.q, self.foot_loads(state, targets))
        self._diagnostics.update(
            com_x_target=targets.com_x,
            roll=state.roll,
            pitch=state.pitch,
        )
        return MotorCommand(
            torque=torque, position=position, velocity=velocity, kp=self._kp, kd=self._kd
        )

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        if self._nominal is None:
            self.reset(sensors)
        else:
            self.estimator.update(sensors)
        state = self.kinematic_state(sensors)
        return self.motor_command(state, self.targets(state, command))

    def diagnostics(self) -> dict[str, float]:
        return dict(self._diagnostics)

    def estimate(self) -> EstimatedState | None:
        return self.estimator.state
