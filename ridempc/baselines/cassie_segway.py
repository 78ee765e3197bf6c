"""Cassie rides the Segway (Segway paper, section IV-B, Fig. 7): the ``pd`` baseline on a Segway.

The standing controller of section IV-A (:class:`~ridempc.baselines.cassie_standing.CassieStanding`)
holds Cassie on the platform; the Segway's own firmware keeps the platform level in pitch and
turns by how far the knee bar is pushed sideways. The paper (IV-B has no equations): "To
accelerate or decelerate, :math:`p_x^{CoM}` is shifted forward or backward. To turn, Cassie
needs to lean into the center bar with her legs, which is accomplished by shifting
:math:`p_y^{CoM}`. [...] The feedback gains on the feet were turned down and the
oscillations ceased. With the crouched posture seen in Fig. 7, Cassie Blue was able to
ride [...] at roughly 4 m/s." The paper's operator set the CoM targets by radio; here two
outer loops set them from the commanded speed and yaw rate:

1. **Crouched posture** (``standing.posture``). Standing tall, Cassie's shins cross the knee
   pad's height (0.45-0.55 m over the platform) 0.13-0.24 m behind the pad: they cannot
   reach it. Crouched to a virtual leg of 0.62 m, the upper shins, just below the knees, are
   at the pad's height and beside it. The shins (radius 0.04 m) must straddle the 0.20 m
   pad: from a stance 0.26 m wide they would clamp it with some 70 N while crouching, and a
   clamp's friction drags the pad and steers the Segway. The ``ride_segway`` stance puts the
   feet 0.335 m apart (hip roll 0.04 rad outward; the paper's "roughly 0.3 m apart"), and
   the crouched posture's hip roll of 0.06 rad leaves each shin a few millimetres off the
   pad, so a lean of a few millimetres pushes it. The hip roll is turned first, over
   ``mount.spread_time``, then the legs shorten from their starting length at
   ``legs.max_speed`` (the standing controller would jump to both at the first tick).
2. **Feet's feedback turned down** (``standing.com_x``, ``standing.joints.toe``): half the
   standing CoP-law gains and less toe damping.
3. **Velocity loop** (shift :math:`p_x^{CoM}`). With the platform's forward speed
   :math:`\\hat v` estimated from the feet (the estimator's
   :class:`~ridempc.estimation.BoardEstimate`: leg odometry fused with the IMU and the
   delayed VIO) along the pelvis heading, low-pass filtered, the CoM x target relative to
   the feet is

   .. math:: x^* = x_0 + k_{ff}^v v^* + k_{\\dot{ff}}^v \\dot v^* + k_p^v (v^* - \\hat v)
       + k_i^v \\textstyle\\int (v^* - \\hat v)\\,dt

   [m], bounded to :math:`x_0 \\pm` ``max_shift``, slewed at most at ``max_rate``, the
   integral held while the output saturates (:class:`ShiftLoop`). Leaning forward moves the
   centre of pressure ahead of the axle, the platform tips forward and the firmware drives
   forward; a steady acceleration :math:`a` needs the CoM about :math:`a h / g` ahead of the
   centre of pressure (:math:`k_{\\dot{ff}}^v`), a steady speed a small lean against the
   firmware's tilt-back (:math:`k_{ff}^v`).
4. **Turning loop** (shift :math:`p_y^{CoM}`). With the yaw rate :math:`\\hat\\omega` of the
   estimated base angular velocity (IMU, world z), the sideways shift

   .. math:: y^* = k_{ff}^\\omega \\omega^* + k_p^\\omega (\\omega^* - \\hat\\omega)
       + k_i^\\omega \\textstyle\\int (\\omega^* - \\hat\\omega)\\,dt

   [m], bounded and slewed likewise, leans both legs by the hip roll
   (:math:`-\\arctan(y^*/\\bar L)`, the standing controller's step 4) about the planted
   feet: the knee on the far side pushes the pad, the bar tilts by :math:`\\delta` and the
   firmware turns at :math:`k_{turn}\\delta` (the identified reduced model, eq. 5',
   :math:`k_{turn} \\approx 8` (rad/s)/rad). Standing still, 0.05 m of shift tilts the bar
   0.08 rad.

Gains: ``cassie_segway.toml`` (:mod:`ridempc.baselines.cassie_segway_gains`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ridempc.baselines.cassie_kinematics import SIDES, KinematicState, LegIndices
from ridempc.baselines.cassie_segway_gains import (
    DEFAULT_GAINS_FILE,
    CassieSegwayGains,
    LoopGains,
    load_segway_gains,
)
from ridempc.baselines.cassie_standing import CassieStanding, StandingTargets
from ridempc.baselines.filters import LowPassFilter
from ridempc.estimation import EstimatedState
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.sensors import SensorPacket

__all__ = ["CassieSegway", "ShiftLoop"]

OUTWARD: dict[str, float] = {"left": 1.0, "right": -1.0}  # sign of an outward hip roll
HIP_ROLL = LegIndices.HIP_ROLL


class ShiftLoop:
    """A command-rate error to a bounded, slewed target shift (steps 3 and 4).

    :math:`s = \\operatorname{clip}(k_{ff} r^* + k_{\\dot{ff}} \\dot r^* + k_p e + k_i I,
    \\pm s_{max})`, :math:`e = r^* - \\hat r`, :math:`\\dot I = e` while
    :math:`|k_i I| <` ``integral_limit`` and the output is not saturated in the error's
    direction; the returned shift moves towards :math:`s` at most at ``max_rate``. The
    measured rate :math:`\\hat r` and the command's rate :math:`\\dot r^*` (finite
    differences; the scenario's ramps) are low-passed at ``filter_hz``.

    Args:
        gains: The loop's gains.
    """

    def __init__(self, gains: LoopGains) -> None:
        self.gains = gains
        self._filter = LowPassFilter(gains.filter_hz)
        self.reset()

    def reset(self) -> None:
        self._filter.reset()
        self._integral = 0.0
        self._shift = 0.0
        self._time: float | None = None
        self._command = 0.0
        self.measured = 0.0
        self.command_rate = 0.0

    def __call__(self, time: float, command: float, measured: float) -> float:
        """The shift [m] for the command and the measured rate at ``time`` [s]."""
        g = self.gains
        dt = 0.0 if self._time is None else max(time - self._time, 0.0)
        rate = (command - self._command) / dt if dt > 0.0 else 0.0
        self._time, self._command = time, command
        self.measured, self.command_rate = (
            float(v) for v in self._filter(time, np.array([measured, rate]))
        )
        error = command - self.measured
        raw = (
            g.feedforward * command
            + g.feedforward_rate * self.command_rate
            + g.kp * error
            + g.ki * self._integral
        )
        saturated = abs(raw) >= g.max_shift and np.sign(raw) == np.sign(error)
        if g.ki > 0.0 and not saturated:
            bound = g.integral_limit / g.ki
            self._integral = min(max(self._integral + error * dt, -bound), bound)
        wanted = min(max(raw, -g.max_shift), g.max_shift)
        step = g.max_rate * dt
        self._shift += min(max(wanted - self._shift, -step), step)
        return self._shift


class CassieSegway(CassieStanding):
    """Rides the Segway: speed by the CoM x target, turns by leaning the legs into the bar.

    Args:
        robot: Cassie.
        board: The Segway's name.
        gains: Checked gains, or the gain file to read (``cassie_segway.toml``).

    Raises:
        ConfigError: The gain file is malformed, or the robot lacks Cassie's joints.
    """

    def __init__(
        self,
        robot: Robot,
        board: str = "segway",
        gains: CassieSegwayGains | Path | str = DEFAULT_GAINS_FILE,
    ) -> None:
        segway = gains if isinstance(gains, CassieSegwayGains) else load_segway_gains(gains)
        super().__init__(robot, board, segway.standing)
        self.segway_gains = segway
        self.velocity_loop = ShiftLoop(segway.velocity)
        self.turning_loop = ShiftLoop(segway.turning)
        self._start: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def reset(self, sensors: SensorPacket) -> None:
        super().reset(sensors)
        state = self.kinematic_state(sensors)
        rolls = [
            OUTWARD[side] * state.motor_position[self.kinematics.legs[side].motors[HIP_ROLL]]
            for side in SIDES
        ]
        self._start = (state.time, float(np.mean(state.leg_length)), float(np.mean(rolls)))
        self.velocity_loop.reset()
        self.turning_loop.reset()

    def forward_speed(self, estimate: EstimatedState) -> float:
        """The platform's speed along the rider's heading, from the feet [m/s]."""
        board = estimate.board
        velocity = board.velocity if board is not None else estimate.base_velocity
        yaw = estimate.yaw
        return float(np.cos(yaw) * velocity[0] + np.sin(yaw) * velocity[1])

    def posture(self, time: float) -> tuple[float, float]:
        """Step 1: the mean leg length [m] and outward hip roll [rad] at ``time`` [s].

        The hip roll turns from its starting value to the posture's over
        ``mount.spread_time``, while Cassie still stands tall with her knees well above the
        pad; then the legs shorten to the crouch at ``legs.max_speed``.
        """
        start_time, start_length, start_roll = self._start
        spread = self.segway_gains.mount.spread_time
        elapsed = time - start_time
        share = min(elapsed / spread, 1.0) if spread > 0.0 else 1.0
        hip_roll = start_roll + share * (self.nominal.hip_roll - start_roll)
        lowered = self.gains.legs.max_speed * max(elapsed - spread, 0.0)
        return max(self.nominal.leg_length, start_length - lowered), hip_roll

    def targets(self, state: KinematicState, command: Command) -> StandingTargets:
        """Steps 1, 3 and 4: the crouch, and the CoM targets from the speed and yaw-rate
        errors."""
        leg_length, hip_roll = self.posture(state.time)
        nominal = replace(self.nominal, leg_length=leg_length, hip_roll=hip_roll)
        estimate = self.estimator.state
        if estimate is None:
            return nominal
        shift_x = self.velocity_loop(state.time, command.velocity, self.forward_speed(estimate))
        shift_y = self.turning_loop(state.time, command.yaw_rate, estimate.yaw_rate)
        self._diagnostics.update(
            speed_estimate=self.velocity_loop.measured,
            yaw_rate_estimate=self.turning_loop.measured,
            com_y_target=nominal.com_y + shift_y,
        )
        return replace(nominal, com_x=nominal.com_x + shift_x, com_y=nominal.com_y + shift_y)
