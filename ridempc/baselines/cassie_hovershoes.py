"""Cassie on the Hovershoes: the hovershoe paper's decoupled controller, eq. (10)-(27).

The ``pd`` baseline for a biped on the ``hovershoes`` board. It extends the standing
controller (:class:`~ridempc.baselines.cassie_standing.CassieStanding`, the paper's
"nominal balancing controller" of [8]) with the paper's four decoupled loops, each a pure
function in :mod:`ridempc.baselines.hovershoe_laws` (signs and where they differ from the
paper's print: there). The feet stand on the shoes, so the shoes' relative position is
read from the legs' kinematics in the **shoes' frame**: x along the feet's mean heading
(each foot's contact line), y to the left, origin between the feet.

- **x-axis** (eq. 10-13): the relative x of the feet sets a toe-angle difference (outer
  loop) that a toe-torque difference :math:`u_5^{\\Delta toe}` realises (inner loop): the
  leading shoe's toe is raised, its platform pitches back and it slows.
- **y-axis** (eq. 14-16): each foot's y against :math:`\\pm y_{offset}` sets its hip-yaw
  target :math:`q_2^{des}` about the posture, held by the hip-yaw motor with stiffness
  :math:`K_p^{q_2}`: the shoe is steered so that, rolling forward, it moves sideways.
  :math:`y_{offset}` is the starting half-spacing of the feet plus the command's
  ``lateral_offset`` (the wave pattern). With ``spread_by_hip_roll`` the standing posture's
  outward hip roll follows, :math:`\\arcsin(\\sin q_1^0 + \\Delta y_{offset} / \\bar L)`
  (mean leg length :math:`\\bar L`), so that the hip-roll hold does not pull the feet back
  to the starting spacing.
- **velocity** (eq. 17): the estimated forward speed (the estimator's base velocity, leg
  odometry fused with the delayed VIO, along the pelvis heading, low-pass filtered) sets
  :math:`COM_x^{des}`, added to the standing CoM target; the standing controller's toe
  pitch (its centre-of-pressure law) then tilts both shoes together.
- **turning** (eq. 18-22): the yaw-rate error (estimated rate about the world's z) adds
  :math:`u_2^{turn}` to both hip yaws and a toe-torque difference :math:`u_5^{turn}` (the
  outer shoe faster), here with the integral feedback the paper suggests for its steady
  error (``ki_pitch``, bounded by ``integral_limit``); the lean :math:`COM_y^{des} =
  K^{shift} L \\arctan(\\dot\\psi v / 9.81)` moves the pelvis sideways over the feet, with
  :math:`L` the CoM's height over the platforms from the kinematics.

They are integrated with the standing controller's torques :math:`\\tilde u` as in eq.
(23)-(27), per leg (``+`` left, ``-`` right):

.. math::
    u_1 = \\tilde u_1, \\quad
    u_2 = \\tilde u_2 + u_2^y + u_2^{turn}, \\quad
    u_{3,4} = \\tilde u_{3,4}(COM_y^{des}), \\quad
    u_5 = \\tilde u_5(COM_x^{des}) \\pm u_5^{\\Delta toe} \\pm u_5^{turn} + u_5^{damping}

where :math:`\\tilde u_2` is the standing controller's hip-yaw feedforward and damping,
:math:`u_2^y` the hip-yaw driver's stiffness towards :math:`q_2^{des}`, and
:math:`u_5^{damping} = -k_d \\dot q_7` the toe driver's damping. One addition to the
nominal hip pitch :math:`\\tilde u_3`: our standing controller leaves the two legs free to
scissor (each hip pitch acts only on the pelvis pitch), which [8]'s joint-space standing
controller does not; on two independent shoes the legs must carry the fore-aft forces that
turn the pair, so ``leg_angle`` adds :math:`\\mp k_p (\\theta_L - \\theta_R)/2` on the hip
pitches (:math:`\\theta` the virtual leg angles). Without it a turn only staggers the shoes.

A shoe in the air (a step's drop; :mod:`ridempc.baselines.hovershoe_flight`, ``[flight]``):
while a leg's shin spring says its foot is unloaded, that toe gets no torque fed forward
and keeps the foot at its last loaded pitch in the world, the leg lengthens to follow its
shoe down, and the CoP law reads the CoM x over the feet held at its last loaded value.
On flat ground no shin relaxes and the law above is the paper's.

The controller runs the state estimator every tick with one platform per foot (left foot
on shoe 0) and reports it through :meth:`estimate`; it never reads ``truth``. Gains:
``cassie_hovershoes.toml`` (:mod:`ridempc.baselines.hovershoe_gains`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ridempc.baselines.cassie_kinematics import SIDES, KinematicState, LegIndices
from ridempc.baselines.cassie_standing import CassieStanding, StandingTargets
from ridempc.baselines.filters import LowPassFilter
from ridempc.baselines.hovershoe_flight import unloaded_feet
from ridempc.baselines.hovershoe_gains import (
    DEFAULT_GAINS_FILE,
    CassieHovershoesGains,
    load_hovershoes_gains,
)
from ridempc.baselines.hovershoe_laws import (
    com_x_target,
    hip_yaw_targets,
    toe_difference_target,
    toe_difference_torque,
    turning,
)
from ridempc.estimation import EstimatedState
from ridempc.frozen import changed
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = ["PLATFORM_FEET", "CassieHovershoes"]

Array = NDArray[np.float64]

PLATFORM_FEET: tuple[tuple[str, ...], ...] = (("left_foot",), ("right_foot",))  # shoe 0, 1
TOE_SIGN: dict[str, float] = {"left": 1.0, "right": -1.0}  # the +- of eq. (27)


class CassieHovershoes(CassieStanding):
    """The hovershoe paper's decoupled controller on top of the standing controller.

    Args:
        robot: Cassie.
        board: The board's name (a ``hovershoes`` kind).
        gains: Checked gains, or the gain file to read (``cassie_hovershoes.toml``).

    Raises:
        ConfigError: The gain file is malformed, or the robot lacks Cassie's joints or feet.
    """

    def __init__(
        self,
        robot: Robot,
        board: str = "hovershoes",
        gains: CassieHovershoesGains | Path | str = DEFAULT_GAINS_FILE,
    ) -> None:
        self.rider_gains = (
            gains if isinstance(gains, CassieHovershoesGains) else load_hovershoes_gains(gains)
        )
        super().__init__(robot, board, self.rider_gains.standing, platforms=PLATFORM_FEET)
        g = self.rider_gains
        self._speed_filter = LowPassFilter(g.velocity.filter_hz)
        self._yaw_rate_filter = LowPassFilter(g.turning.filter_hz)
        self._stagger_filter = LowPassFilter(g.x_axis.filter_hz)
        self._feet_y_filter = LowPassFilter(g.y_axis.filter_hz)
        self._half_spacing = 0.0
        self._speed = 0.0
        self._yaw_rate = 0.0
        self._yaw_integral = 0.0
        self._integral_time: float | None = None
        self._unloaded = np.zeros(2, dtype=bool)
        self._loaded_com_x = np.zeros(2)  # CoM x over the feet and its rate, last loaded
        self._loaded_pitch = np.zeros(2)  # each foot's pitch, last loaded [rad]
        self._time = 0.0
        self._extension = np.zeros(2)  # each leg's length added to reach its falling shoe [m]
        self._unloaded_for = np.zeros(2)  # how long each foot has been unloaded [s]

    # ------------------------------------------------------------------ state

    def reset(self, sensors: SensorPacket) -> None:
        """Standing posture, estimator and the nominal half-spacing from the first packet."""
        super().reset(sensors)
        feet = self._feet(self.kinematic_state(sensors))
        self._half_spacing = 0.5 * float(feet[0, 1] - feet[1, 1])
        self._yaw_integral = 0.0
        self._integral_time = None
        self._unloaded[:] = False
        self._loaded_com_x[:] = 0.0
        self._extension[:] = 0.0
        self._unloaded_for[:] = 0.0
        self._loaded_pitch = self._foot_pitches(self.kinematic_state(sensors))
        for low_pass in (
            self._speed_filter,
            self._yaw_rate_filter,
            self._stagger_filter,
            self._feet_y_filter,
        ):
            low_pass.reset()

    @staticmethod
    def _feet(state: KinematicState) -> Array:
        """Each foot's contact-line centre (left, right) in the shoes' frame [m], 2 x 2.

        The frame's x axis is the feet's mean heading (each foot's contact line, back to
        front), its y axis points left and its origin is the midpoint of the two feet. The
        feet stand on the shoes, so this is the shoes' frame: the relative x and the
        spacing of the shoes, whatever the pelvis' yaw over the feet.
        """
        contacts = state.contacts[:, :2]
        axes = contacts[0::2] - contacts[1::2]  # front minus back, per foot
        heading = axes[0] / np.linalg.norm(axes[0]) + axes[1] / np.linalg.norm(axes[1])
        heading /= np.linalg.norm(heading)
        left = np.array([-heading[1], heading[0]])
        centres = 0.5 * (contacts[0::2] + contacts[1::2])
        offsets = centres - centres.mean(axis=0)
        return np.column_stack([offsets @ heading, offsets @ left])

    def _estimated_motion(self, estimate: EstimatedState, time: float) -> tuple[float, float]:
        """Forward speed [m/s] and yaw rate [rad/s] from the estimator, low-pass filtered."""
        yaw = estimate.yaw
        heading = np.array([np.cos(yaw), np.sin(yaw)])
        speed = float(heading @ estimate.base_velocity[:2])
        yaw_rate = estimate.yaw_rate
        self._speed = float(self._speed_filter(time, np.array([speed]))[0])
        self._yaw_rate = float(self._yaw_rate_filter(time, np.array([yaw_rate]))[0])
        return self._speed, self._yaw_rate

    # ------------------------------------------------------------------ law

    def rider_targets(
        self, state: KinematicState, command: Command, speed: float, yaw_rate: float
    ) -> tuple[StandingTargets, float]:
        """The standing targets moved by eq. (17) and (21)-(22), and :math:`y_{offset}`.

        Returns:
            The standing targets and the desired half-spacing :math:`y_{offset}` [m].
        """
        g = self.rider_gains
        nominal = self.nominal
        com_height = float(state.com[2] - state.support_centre[2])
        turn = turning(g.turning, yaw_rate, command.yaw_rate, speed, com_height)
        y_offset = self._half_spacing + command.lateral_offset
        hip_roll = nominal.hip_roll
        if g.y_axis.spread_by_hip_roll:
            reach = float(np.mean(state.leg_length))
            hip_roll = float(
                np.arcsin(np.clip(np.sin(hip_roll) + command.lateral_offset / reach, -1.0, 1.0))
            )
        targets = changed(
            nominal,
            com_x=nominal.com_x + com_x_target(g.velocity, speed, command.velocity),
            com_y=turn.com_y,
            hip_roll=hip_roll,
        )
        self._diagnostics.update(
            speed_estimate=speed,
            yaw_rate_estimate=yaw_rate,
            yaw_rate_error=turn.yaw_rate_error,
            tilt=turn.tilt,
            com_y_target=turn.com_y,
            y_offset=y_offset,
        )
        return targets, y_offset

    def rider_command(
        self,
        state: KinematicState,
        command: Command,
        nominal: MotorCommand,
        y_offset: float,
        speed: float,
        yaw_rate: float,
    ) -> MotorCommand:
        """Eq. (24) and (27): the hip-yaw and toe terms added to the standing command."""
        g = self.rider_gains
        feet = self._feet(state)
        smoothed = self._stagger_filter(state.time, np.array([feet[0, 0] - feet[1, 0]]))
        feet_y = self._feet_y_filter(state.time, feet[:, 1])
        legs = {side: self.kinematics.legs[side].motors for side in SIDES}
        toe = {side: legs[side][LegIndices.TOE] for side in SIDES}
        hip_yaw = {side: legs[side][LegIndices.HIP_YAW] for side in SIDES}
        hip_pitch = {side: legs[side][LegIndices.HIP_PITCH] for side in SIDES}
        scissor = float(state.leg_angle[0] - state.leg_angle[1])
        q, dq = state.motor_position, state.motor_velocity

        # x-axis, eq. (10)-(13)
        toe_target = toe_difference_target(g.x_axis, float(smoothed[0]), 0.0)
        u_toe = toe_difference_torque(
            g.x_axis,
            float(q[toe["left"]] - q[toe["right"]]),
            float(dq[toe["left"]] - dq[toe["right"]]),
            toe_target,
        )
        # y-axis, eq. (14)-(16); turning, eq. (18)-(20)
        yaw_targets = hip_yaw_targets(g.y_axis, float(feet_y[0]), float(feet_y[1]), y_offset)
        turn = turning(
            g.turning,
            yaw_rate,
            command.yaw_rate,
            speed,
            0.0,
            self._integrate(state.time, yaw_rate - command.yaw_rate),
        )

        torque = nominal.torque.copy()
        position = nominal.position.copy()
        kp = nominal.kp.copy()
        kd = nominal.kd.copy()
        for side, yaw_target in zip(SIDES, yaw_targets, strict=True):
            sign = TOE_SIGN[side]
            position[hip_yaw[side]] += yaw_target  # about the posture, eq. (15)
            kp[hip_yaw[side]] = g.y_axis.kp_hip_yaw  # u_2^y, eq. (16)
            torque[hip_yaw[side]] += turn.hip_yaw_torque  # u_2^turn, eq. (24)
            torque[toe[side]] += sign * (u_toe + turn.toe_torque)  # eq. (27)
            kd[toe[side]] = g.toe_damping.kd  # u_5^damping, eq. (27)
            torque[hip_pitch[side]] -= sign * 0.5 * g.leg_angle.kp * scissor  # eq. (25)
        self._diagnostics.update(
            stagger=float(feet[0, 0] - feet[1, 0]),
            half_spacing=0.5 * float(feet[0, 1] - feet[1, 1]),
            toe_difference_target=toe_target,
            toe_difference_torque=u_toe,
            turn_toe_torque=turn.toe_torque,
            turn_hip_yaw_torque=turn.hip_yaw_torque,
            left_hip_yaw_target=yaw_targets[0],
            right_hip_yaw_target=yaw_targets[1],
        )
        return changed(nominal, torque=torque, position=position, kp=kp, kd=kd)

    def _integrate(self, time: float, error: float) -> float:
        """:math:`\\int e_{yaw} dt` [rad], held where its toe torque reaches ``integral_limit``."""
        gains = self.rider_gains.turning
        dt = 0.0 if self._integral_time is None else max(time - self._integral_time, 0.0)
        self._integral_time = time
        if gains.ki_pitch > 0.0:
            bound = gains.integral_limit / gains.ki_pitch
            self._yaw_integral = min(max(self._yaw_integral + error * dt, -bound), bound)
        return self._yaw_integral

    # ------------------------------------------------------------------ flight

    def flight_state(self, state: KinematicState) -> KinematicState:
        """The state the CoP law reads: its CoM x and rate held while a foot is unloaded.

        Records which feet are unloaded (:func:`unloaded_feet`, from the shin springs) and,
        while both are loaded, the CoM x over the feet, its rate and the feet's pitches.
        """
        gains = self.rider_gains.flight
        shins = np.array([state.q[self.kinematics.legs[s].q[LegIndices.SHIN]] for s in SIDES])
        self._unloaded = unloaded_feet(shins, gains.unloaded_shin)
        dt = max(state.time - self._time, 0.0)
        self._time = state.time
        if gains.unloaded_shin == 0.0:
            return state
        self._unloaded_for = np.where(self._unloaded, self._unloaded_for + dt, 0.0)
        falling = self._unloaded_for >= gains.reach_delay
        reach = np.where(falling, gains.extend_speed, -self.gains.legs.max_speed)
        reach[self._unloaded & ~falling] = 0.0
        self._extension = np.clip(self._extension + reach * dt, 0.0, gains.max_extension)
        if not self._unloaded.any():
            self._loaded_com_x = np.array([state.com_offset[0], state.com_velocity[0]])
            self._loaded_pitch = self._foot_pitches(state)
            return state
        com = state.com.copy()
        com[0] = state.support_centre[0] + self._loaded_com_x[0]
        com_velocity = state.com_velocity.copy()
        com_velocity[0] = self._loaded_com_x[1]
        return changed(state, com=com, com_velocity=com_velocity)

    def leg_extension(self, side: str) -> float:
        """An unloaded leg reaches down after its falling shoe; loaded again, it shortens back
        at the posture's slew rate, so the rider comes down the step over the legs' stroke."""
        return float(self._extension[SIDES.index(side)])

    def hold_ankles(self, state: KinematicState, command: MotorCommand) -> MotorCommand:
        """An unloaded foot's toe turned to keep the foot at its last loaded pitch in the
        world (the shoe lands as it left), no torque fed forward."""
        if not self._unloaded.any() or self.rider_gains.flight.unloaded_shin == 0.0:
            return command
        torque, position = command.torque.copy(), command.position.copy()
        kp = command.kp.copy()
        pitches = self._foot_pitches(state)
        for i, side in enumerate(SIDES):
            if self._unloaded[i]:
                toe = self.kinematics.legs[side].motors[LegIndices.TOE]
                torque[toe] = 0.0
                error = pitches[i] - self._loaded_pitch[i]
                position[toe] = state.motor_position[toe] - error
                kp[toe] = self.rider_gains.flight.kp_toe
        self._diagnostics.update(
            left_unloaded=float(self._unloaded[0]), right_unloaded=float(self._unloaded[1])
        )
        return changed(command, torque=torque, position=position, kp=kp)

    @staticmethod
    def _foot_pitches(state: KinematicState) -> Array:
        """Each foot's pitch in the heading frame (left, right) [rad], positive nose up."""
        axes = state.contacts[0::2] - state.contacts[1::2]  # front minus back
        return np.arctan2(axes[:, 2], np.hypot(axes[:, 0], axes[:, 1]))

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        if self._nominal is None:
            self.reset(sensors)
            estimate = self.estimator.state
        else:
            estimate = self.estimator.update(sensors)
        assert estimate is not None
        state = self.flight_state(self.kinematic_state(sensors))
        speed, yaw_rate = self._estimated_motion(estimate, sensors.time)
        targets, y_offset = self.rider_targets(state, command, speed, yaw_rate)
        nominal = self.motor_command(state, targets)
        return self.hold_ankles(
            state, self.rider_command(state, command, nominal, y_offset, speed, yaw_rate)
        )
