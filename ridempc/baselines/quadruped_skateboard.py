"""The quadruped's PD baseline on the skateboard: four-leg balancing, deck roll by torso shift.

What a careful engineer writes without optimisation, for the skateboard paper's four-leg
balancing mode (Sec. III-B, VI-A: "Robot steers skateboard by adjusting its torso lateral
position"). It reads only the sensor packet: IMU orientation and rate, motor encoders and
torques, and the VIO's forward speed for steering. Per tick (500 Hz):

1. **Feet and deck** (:meth:`QuadrupedSkateboardPD.observe`). Foot centres :math:`p_i^B` and
   velocities :math:`\\dot p_i^B = \\omega \\times p_i^B + J_i \\dot q_i` in the trunk frame
   from the encoders (:mod:`ridempc.baselines.quadruped_legs`), turned into the *feet frame*
   F: gravity-aligned (roll and pitch from the IMU), yawed along the line from the rear to the
   front feet, origin at the feet's centroid. The feet press into the deck by
   :math:`c\\, f_i` (contact compliance :math:`c`, vertical load :math:`f_i` from the motor
   torques, :math:`f_i^B = -J_i^{-\\top}(\\tau_i - g_i(q))`), so each centre is lifted by that
   much before the plane through the four of them gives the deck's roll :math:`\\hat\\varphi`
   and rate :math:`\\dot{\\hat\\varphi}` (:mod:`ridempc.baselines.quadruped_support`).
2. **Roll reference.** :math:`\\varphi^* = \\mathrm{clip}(\\varphi_{cmd} + \\varphi_{steer})`,
   where a yaw-rate command becomes a roll by eq. (14),
   :math:`\\sin\\varphi_{steer} = -\\dot\\psi^* K_{board} / v`, once the board rolls at
   :math:`v \\ge v_{min}` (VIO speed), within the stance's roll
   (:class:`~ridempc.boards.skateboard.steering.RollSteering`); :math:`\\dot\\varphi^*,
   \\ddot\\varphi^*` by differences.
3. **Lateral shift of the centre of mass** to the right (-y), :math:`u`, that rolls the deck.
   The reduced roll model, eqs. (6)-(7), :math:`I_{Bx}\\ddot\\varphi = \\tau - K_B\\varphi -
   B_B\\dot\\varphi`, takes the rider's roll torque about the deck's top centre, and a rider
   whose centre of pressure is :math:`p` to the left of that point (level frame) puts
   :math:`\\tau = -m g\\, p` on it. The centre of mass must lead the centre of pressure as the
   linear inverted pendulum says, :math:`c = p + (h/g)\\,\\ddot c`. So, with the trunk level,

   .. math:: u_{ff} = \\frac{K_B\\varphi^* + B_B\\dot\\varphi^* + I_{Bx}\\ddot\\varphi^*}{m g}
             + \\frac{h}{g}\\frac{K_B \\ddot\\varphi^*}{m g}, \\qquad
             u_{fb} = \\mathcal{F}_2\\big[k_p e + k_d \\dot e
             + k_i \\textstyle\\int e\\,dt\\big], \\quad e = \\varphi^* - \\hat\\varphi

   [m], where :math:`\\mathcal{F}_2` is a critically damped second-order low-pass of natural
   frequency :math:`\\omega_{fb}`. :math:`u_{ff}` is scaled by ``feedforward``
   (:math:`1 - m g a / K_B`): the feet, and the centre of mass held over them, ride the deck's
   top, :math:`a` above its roll axis near axle height, which the identified :math:`K_B`
   (torques about the top of a deck under a rigid weight) leaves out. (A rider rolling
   rigidly with the deck would need
   :math:`\\Delta y = \\varphi (K_B - m g h)/(m g)` in the deck's frame: the same point.)
   The commanded shift follows :math:`u_s = S \\tanh((u_{ff} + u_{fb}) / S)` (a smooth bound
   ``max_shift``) as a critically damped second-order system with its rate fed forward and
   its acceleration bounded,
   :math:`\\ddot u = \\mathrm{clip}(\\omega_u^2 (u_s - u) + 2\\omega_u (\\dot u_s - \\dot u),
   \\pm a_{max})`. Everything here is slow on purpose: moving the centre of mass sideways
   first moves the centre of pressure the other way (by :math:`-(h/g)\\ddot c`), the deck and
   the robot on it have a lightly damped roll mode near 9-15 rad/s, and a fast shift (a step
   in the reference's slope, a fast feedback) rings it up until the far feet unload. On flat
   ground (board ``none``) there is no deck to roll: :math:`u = 0`.
4. **Trunk pose over the feet.** Centre of mass at :math:`c^* = (x^*_c, -u)` in F (over the
   feet's centroid), trunk origin at the held height over the centroid, trunk level (roll 0,
   pitch :math:`\\theta^*`) and at its starting yaw relative to the feet. Each tick's change is
   bounded (``max_correction``, ``max_rotation``).
5. **Joint targets by inverse kinematics.** The feet keep their starting stance on the deck,
   :math:`p_i^{F*} = (x_i^0,\\ y_i^0 \\cos\\hat\\varphi,\\ z_i^F)`, so a foot that slips or
   unloads is brought back; :math:`p_i^{B*} = R^{*\\top}(p_i^{F*} - o^*)`,
   :math:`q_i^* = IK(p_i^{B*})` (closed form). The velocity targets
   :math:`\\dot q_i^* = J_i^{-1} R^{*\\top}(\\dot p_i^F - \\bar{\\dot p}^F - \\dot o^*)` let the
   feet move with the deck about their centroid and the trunk at the shift's rate, so the
   joint damping acts on the trunk's motion over the feet, not on the deck's roll (the
   obvious alternative, the feet's rigid turn at the filtered roll rate, tracked a little
   worse: measured).
6. **Feedforward.** Vertical loads :math:`f_i` whose centre of pressure is under :math:`c^*`
   (:func:`~ridempc.baselines.quadruped_support.vertical_loads`), plus a roll-rate term
   :math:`\\Delta f_i = -D\\, \\dot{\\hat\\varphi}\\, y_i / \\sum_j y_j^2` that lightens the deck's
   rising side, mapped by :math:`\\tau_i = g_i(q) - J_i^\\top R_{FB}^\\top (0, 0, f_i)` with the
   legs' own gravity torques :math:`g_i(q)` (Pinocchio). Without :math:`g_i` the joint PD
   carries the legs' weight, and the small inward squeeze that leaves makes the feet creep.
   The roll-rate term damps the deck's roll mode through the trunk: a load difference puts a
   torque :math:`\\tau` on the deck and :math:`-\\tau` on the trunk, and the trunk's posture loop
   (natural frequency :math:`\\omega_t`) hands it back to the deck amplified by
   :math:`1/(1 - \\omega^2/\\omega_t^2)`, so the net torque on the deck is
   :math:`D\\,\\omega^2/(\\omega_t^2 - \\omega^2)\\,\\dot\\varphi` against the roll: damping that
   grows towards the deck's mode and vanishes at the 3 s reference. (Pressing the rising side
   instead, the obvious sign, undamps it: measured.)
7. **Sideways stiffness by grip.** Each leg's abad gains are scaled by its share of the
   weight, :math:`\\mathrm{clip}(4 f_i / m g)`, so that a sideways error loads the feet in
   proportion to their normal force.

Motor command per joint: :math:`\\tau = \\tau_{ff} + k_p (q^* - q) + k_d (\\dot q^* - \\dot
q)`, run by the drivers at the physics rate. Gains: ``quadruped_skateboard.toml``, or the
file the pair file names (``pd_gains``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.baselines.quadruped_legs import QuadrupedLegs
from ridempc.baselines.quadruped_skateboard_gains import (
    QuadrupedSkateboardGains,
    gains_file,
    load_quadruped_skateboard_gains,
)
from ridempc.baselines.quadruped_support import SupportPlane, fit_support_plane, vertical_loads
from ridempc.boards import support_height
from ridempc.boards.registry import load_board
from ridempc.boards.skateboard.parameters import (
    SkateboardParameters,
    SkateboardReducedParameters,
)
from ridempc.boards.skateboard.steering import RollSteering
from ridempc.controllers.base import Controller
from ridempc.errors import ConfigError
from ridempc.estimation import EstimatedState, StateEstimator
from ridempc.estimation.lapack import pinv, solve
from ridempc.gravity import GRAVITY
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.rotations import exp3, quaternion_to_matrix, rotation_y, rotation_z
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = ["QuadrupedSkateboardPD", "StanceState"]

Array = NDArray[np.float64]


def _limited_rotation(current: Array, wanted: Array, limit: float) -> Array:
    """``wanted``, or the rotation ``limit`` [rad] from ``current`` towards it."""
    error = wanted @ current.T
    angle = math.acos(max(-1.0, min(1.0, (float(np.trace(error)) - 1.0) / 2.0)))
    if angle <= limit:
        return wanted
    axis = np.array(
        [error[2, 1] - error[1, 2], error[0, 2] - error[2, 0], error[1, 0] - error[0, 1]]
    )
    axis *= limit / np.linalg.norm(axis)
    return exp3(axis) @ current


def _leg_solve(a: Array, b: Array) -> Array:
    """:math:`a^{-1} b` for a leg's 3 x 3 Jacobian (or its transpose); for a leg at a
    singularity (the knee straight, read exactly so from the quantised encoders: the hip's
    pitch and the knee move the foot the same way, and the foot's force along the leg loads
    no joint), the least-norm solution :math:`a^+ b`, which leaves that direction at zero
    rather than ending the ride (Go1 `hard` seed 193 v0008, standby under the MPC)."""
    try:
        return solve(a, b)
    except np.linalg.LinAlgError:
        return pinv(a) @ b


def _row_mean(rows: Array) -> Array:
    """The mean of ``rows`` (n x k) over its rows: ``np.mean(rows, axis=0)``'s own sum and
    division, bit for bit, without its argument handling (a few us, four times a tick)."""
    return np.add.reduce(rows, axis=0) / len(rows)


def _foot_radius(robot: Robot) -> float:
    """Radius of the foot spheres [m] (their centres are the contact frames)."""
    model = robot.mj_model
    bodies = {
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in robot.params.foot_bodies
    }
    radii = [
        float(model.geom_size[g, 0])
        for g in range(model.ngeom)
        if model.geom_bodyid[g] in bodies and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE
    ]
    return max(radii, default=0.0)


def _roll_model(board: str) -> SkateboardReducedParameters | None:
    """The deck's identified roll model, or None on flat ground."""
    loaded = load_board(board)
    if loaded is None:
        return None
    params = loaded.params
    if not isinstance(params, SkateboardParameters):
        raise ConfigError(
            f"controller 'pd' for a quadruped rides board 'skateboard' or 'none', not '{board}'"
        )
    if params.reduced is None:
        raise ConfigError(f"board '{board}': no identified [reduced] roll model in board.toml")
    return params.reduced


def _clip(value: float, bound: float) -> float:
    return max(-bound, min(bound, value))


@dataclass(frozen=True)
class StanceState:
    """What the controller reads from one sensor packet, in the feet frame F.

    Attributes:
        q: Motor angles [rad], actuator order.
        feet: Foot centres in F (4 x 3) [m].
        feet_velocity: Their velocities in F (4 x 3) [m/s].
        jacobians: Each leg's :math:`J_i` at ``q`` (4 x 3 x 3) [m/rad].
        trunk_rotation: :math:`R_{FB}`.
        trunk_origin: Trunk origin in F [m].
        com: Centre of mass in the trunk frame [m].
        leg_gravity: Gravity torque of the links beyond each motor, :math:`g(q)` [N m].
        loads: Vertical load of each foot from the motor torques [N].
        deck: The plane through the feet, corrected for their sinking into the deck.
    """

    q: Array
    feet: Array
    feet_velocity: Array
    jacobians: Array
    trunk_rotation: Array
    trunk_origin: Array
    com: Array
    leg_gravity: Array
    loads: Array
    deck: SupportPlane


class QuadrupedSkateboardPD(Controller):
    """Four-leg balancing on a skateboard (or flat ground), deck roll by torso lateral shift.

    Args:
        robot: A quadruped with abad-hip-knee legs.
        board: ``skateboard`` (a board of kind skateboard with its reduced model) or ``none``.
        gains: Checked gains, or their file; by default the one the pair file names
            (:func:`~ridempc.baselines.quadruped_skateboard_gains.gains_file`).

    Raises:
        ConfigError: Malformed gains, a robot whose legs are not abad-hip-knee chains, a
            board that is not a skateboard, or a skateboard without its identified model.
    """

    def __init__(
        self,
        robot: Robot,
        board: str = "skateboard",
        gains: QuadrupedSkateboardGains | Path | str | None = None,
    ) -> None:
        super().__init__(robot, board)
        self.gains = (
            gains
            if isinstance(gains, QuadrupedSkateboardGains)
            else load_quadruped_skateboard_gains(gains or gains_file(robot.name, board))
        )
        self.rate_hz = self.gains.rate_hz
        self.roll_model = _roll_model(board)
        self.steering = (  # a yaw rate to a deck roll, eq. (14)
            RollSteering(gain=self.roll_model.steer_gain, min_speed=self.gains.steering.min_speed)
            if self.roll_model is not None
            else None
        )
        motor_joints = tuple(m.joint for m in robot.motors)
        self.legs = QuadrupedLegs(
            build_pinocchio_robot(robot), robot.params.contact_sites, motor_joints
        )
        if len(self.legs.legs) != 4:
            raise ConfigError(f"robot '{robot.name}': {len(self.legs.legs)} legs, expected 4")
        self.n_motors = len(robot.motors)
        self.mass = robot.mass
        self.foot_radius = _foot_radius(robot)
        self._front = np.array([leg.hip[0] > 0.0 for leg in self.legs.legs])
        if self._front.sum() != 2:
            raise ConfigError(f"robot '{robot.name}': expected two front and two rear legs")
        self._front_rows = np.flatnonzero(self._front)
        self._rear_rows = np.flatnonzero(~self._front)
        self._leg_joints = [np.array(leg.motors) for leg in self.legs.legs]
        self._kp = np.zeros(self.n_motors)
        self._kd = np.zeros(self.n_motors)
        joints = self.gains.joints
        for leg in self.legs.legs:
            for motor, pd in zip(leg.motors, (joints.abad, joints.hip, joints.knee), strict=True):
                self._kp[motor], self._kd[motor] = pd.kp, pd.kd
        self._abad = np.array([leg.motors[0] for leg in self.legs.legs])
        self._ready = False
        self._height = 0.0  # [m] trunk origin over the feet's centroid
        self._stance = np.zeros((4, 2))  # [m] the feet's (x, y) about their centroid
        self._relative_yaw = 0.0  # [rad] trunk yaw in F
        self._previous: tuple[float, float, float] | None = None  # time, roll ref, its rate
        self._last_update: float | None = None  # [s] the packet time of the last shift update
        self._roll_rate = 0.0  # [rad/s] filtered
        self._roll_integral = 0.0  # [m]
        self._feedback = (0.0, 0.0)  # filtered feedback shift [m], [m/s]
        self._shift = (0.0, 0.0)  # commanded shift [m], [m/s]
        self._diagnostics: dict[str, float] = {}
        # Not used by the control law (the deck is read from the feet above); it runs so that
        # every ride reports the estimator's error against the truth.
        feet = robot.params.foot_bodies
        self.estimator = StateEstimator(
            robot,
            platforms=(feet,) if board != "none" else (),
            support_height=support_height(board),
        )

    # ------------------------------------------------------------------ state

    def observe(self, sensors: SensorPacket) -> StanceState:
        """The stance in the feet frame, from the IMU, encoders and motor torques."""
        n = self.n_motors
        q = np.asarray(sensors.joint_position[:n], dtype=float)
        dq = np.asarray(sensors.joint_velocity[:n], dtype=float)
        tau = np.asarray(sensors.motor_torque, dtype=float)
        rotation_wb = quaternion_to_matrix(sensors.imu.quaternion)
        yaw = math.atan2(rotation_wb[1, 0], rotation_wb[0, 0])
        rotation_lb = rotation_z(-yaw) @ rotation_wb  # level frame, yawed with the trunk
        wx, wy, wz = np.asarray(sensors.imu.angular_velocity, dtype=float).tolist()
        omega_cross = np.array([[0.0, -wz, wy], [wz, 0.0, -wx], [-wy, wx, 0.0]])
        feet_b = np.empty((4, 3))
        velocities_b = np.empty((4, 3))
        jacobians = np.empty((4, 3, 3))
        for i, (leg, joints) in enumerate(zip(self.legs.legs, self._leg_joints, strict=True)):
            feet_b[i], jacobians[i] = leg.position_and_jacobian(q[joints])
            velocities_b[i] = omega_cross @ feet_b[i] + jacobians[i] @ dq[joints]
        feet_l = feet_b @ rotation_lb.T
        heading = _row_mean(feet_l[self._front_rows]) - _row_mean(feet_l[self._rear_rows])
        rotation_fl = rotation_z(-math.atan2(heading[1], heading[0]))
        rotation_fb = rotation_fl @ rotation_lb
        centroid = _row_mean(feet_l)
        feet = (feet_l - centroid) @ rotation_fl.T
        velocities = velocities_b @ rotation_fb.T
        com, leg_gravity = self.legs.com_and_gravity(q, rotation_fb)
        loads = np.empty(4)
        for i, joints in enumerate(self._leg_joints):
            force_b = _leg_solve(jacobians[i].T, leg_gravity[joints] - tau[joints])
            loads[i] = float(rotation_fb[2] @ force_b)
        pressed = feet.copy()
        pressed[:, 2] += self.gains.contact.compliance * np.maximum(loads, 0.0)
        return StanceState(
            q=q,
            feet=feet,
            feet_velocity=velocities,
            jacobians=jacobians,
            trunk_rotation=rotation_fb,
            trunk_origin=-(rotation_fl @ centroid),
            com=com,
            leg_gravity=leg_gravity,
            loads=loads,
            deck=fit_support_plane(pressed, velocities),
        )

    def reset(self, sensors: SensorPacket) -> None:
        state = self.observe(sensors)
        height = self.gains.posture.height
        self._height = float(state.trunk_origin[2]) if height is None else height
        self._stance = state.feet[:, :2].copy()
        rotation = state.trunk_rotation
        self._relative_yaw = math.atan2(rotation[1, 0], rotation[0, 0])
        self._previous = None
        self._last_update = None
        self._roll_rate = 0.0
        self._roll_integral = 0.0
        self._feedback = (0.0, 0.0)
        self._shift = (0.0, 0.0)
        self.estimator.reset(sensors)
        self._ready = True

    # ------------------------------------------------------------------ references

    def roll_reference(self, sensors: SensorPacket, command: Command) -> tuple[float, float, float]:
        """:math:`(\\varphi^*, \\dot\\varphi^*, \\ddot\\varphi^*)` [rad, rad/s, rad/s^2]."""
        assert self.steering is not None
        steering = self.gains.steering
        speed = 0.0
        if sensors.vio is not None:
            vio = sensors.vio
            speed = math.cos(vio.yaw) * vio.velocity[0] + math.sin(vio.yaw) * vio.velocity[1]
        roll = command.roll + self.steering.roll(command.yaw_rate, speed)
        roll = _clip(roll, steering.max_roll)
        rate = acceleration = 0.0
        if self._previous is not None:
            last_time, last_roll, last_rate = self._previous
            dt = sensors.time - last_time
            if dt > 0.0:
                rate = (roll - last_roll) / dt
                acceleration = (rate - last_rate) / dt
        self._previous = (sensors.time, roll, rate)
        return roll, rate, acceleration

    def _step(self, time: float) -> float:
        """The time the filters advance by [s]: the control ticks since the last update, at
        least one. A backup in standby is updated every few ticks only, and its filters must
        keep the ride's time, or it is handed a shift that lags the deck by as many periods."""
        last, self._last_update = self._last_update, time
        ticks = 1 if last is None else max(1, round((time - last) * self.rate_hz))
        return ticks / self.rate_hz

    def lateral_shift(
        self,
        sensors: SensorPacket,
        command: Command,
        state: StanceState,
        integrate: bool = True,
    ) -> tuple[float, float]:
        """The centre of mass's shift to the right :math:`u` [m] and its rate [m/s]; zero on
        flat ground.

        Args:
            sensors: This tick's packet.
            command: The ride's command.
            state: The stance observed this tick.
            integrate: Whether the roll error's integral advances; held (not integrated)
                while this law is in standby (:meth:`standby`).
        """
        model = self.roll_model
        if model is None:
            return 0.0, 0.0
        gains = self.gains.roll
        dt = self._step(sensors.time)
        reference, reference_rate, reference_acceleration = self.roll_reference(sensors, command)
        weight = self.mass * GRAVITY
        com_height = float((state.trunk_origin + state.trunk_rotation @ state.com)[2])
        com_height += self.foot_radius
        # centre of pressure that rolls the deck as the reference does, eqs. (6)-(7), and the
        # centre of mass over it, c = p + (h / g) c'' (linear inverted pendulum)
        stiffness = model.roll_stiffness
        pressure = (
            stiffness * reference
            + model.roll_damping * reference_rate
            + model.roll_inertia * reference_acceleration
        ) / weight
        lead = com_height / GRAVITY * stiffness * reference_acceleration / weight
        feedforward = gains.feedforward * (pressure + lead)
        feedforward_rate = gains.feedforward * (
            (stiffness * reference_rate + model.roll_damping * reference_acceleration) / weight
        )
        # feedback on the deck's roll, slowly (see the module's docstring)
        alpha = dt / (gains.rate_filter + dt)
        self._roll_rate += alpha * (state.deck.roll_rate - self._roll_rate)
        error = reference - state.deck.roll
        error_rate = reference_rate - self._roll_rate
        if integrate:
            self._roll_integral = _clip(
                self._roll_integral + gains.ki * error * dt, gains.integral_limit
            )
        raw = gains.kp * error + gains.kd * error_rate + self._roll_integral
        w = gains.feedback_bandwidth
        feedback, feedback_rate = self._feedback
        feedback_rate += dt * (w * w * (raw - feedback) - 2.0 * w * feedback_rate)
        feedback += dt * feedback_rate
        self._feedback = (feedback, feedback_rate)
        # the commanded shift follows a smooth saturation of the sum with bounded acceleration
        bound = gains.max_shift
        squash = math.tanh((feedforward + feedback) / bound)
        wanted = bound * squash
        wanted_rate = (1.0 - squash * squash) * (feedforward_rate + feedback_rate)
        w = gains.follow_bandwidth
        shift, shift_rate = self._shift
        acceleration = w * w * (wanted - shift) + 2.0 * w * (wanted_rate - shift_rate)
        shift_rate += dt * _clip(acceleration, gains.max_acceleration)
        shift += dt * shift_rate
        self._shift = (shift, shift_rate)
        self._diagnostics.update(
            roll_reference=reference,
            roll_error=error,
            shift_feedforward=feedforward,
            shift_feedback=feedback,
            roll_integral=self._roll_integral,
        )
        return shift, shift_rate

    # ------------------------------------------------------------------ control

    def standby(self, sensors: SensorPacket, command: Command) -> None:
        """The estimator and the roll's filters (:meth:`lateral_shift`) advanced, no
        command (the legs' inverse kinematics and torques left out).

        The roll error's integral is held, not advanced (conditional integration, the
        standard anti-windup): in standby another law rolls the deck, so the error is not
        this law's to remove, and integrated over a ride it winds the integral towards its
        limit (a third of the feet's half-spacing), which a law handed the ride mid-push
        then shifts the centre of mass by on top of the push.
        """
        self._advance(sensors, command, integrate=False)

    def _advance(
        self, sensors: SensorPacket, command: Command, integrate: bool = True
    ) -> tuple[StanceState, tuple[float, float]]:
        """What a tick carries to the next: the estimator, the stance, the shift's filters
        (the roll error's integral only where ``integrate``)."""
        if not self._ready:
            self.reset(sensors)
        else:
            self.estimator.update(sensors)
        state = self.observe(sensors)
        return state, self.lateral_shift(sensors, command, state, integrate)

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        state, (shift, shift_rate) = self._advance(sensors, command)
        posture = self.gains.posture

        # trunk: level, pitch held, starting yaw over the feet; centre of mass over the deck
        deck_point = -self.foot_radius * state.deck.normal
        wanted_rotation = rotation_z(self._relative_yaw) @ rotation_y(posture.pitch)
        rotation = _limited_rotation(state.trunk_rotation, wanted_rotation, posture.max_rotation)
        com_target = np.array([posture.com_x, -shift])  # over the feet's centroid
        origin = np.append(com_target - (rotation @ state.com)[:2], self._height)
        step = origin - state.trunk_origin
        distance = float(np.linalg.norm(step))
        if distance > posture.max_correction:
            origin = state.trunk_origin + step * (posture.max_correction / distance)
        origin_rate = np.array([0.0, -shift_rate, 0.0])

        # legs: the feet keep their stance on the deck, the trunk moves to (origin, rotation)
        feet = state.feet.copy()
        feet[:, 0] = self._stance[:, 0]
        feet[:, 1] = self._stance[:, 1] * math.cos(state.deck.roll)
        loads = self.gains.force.weight_fraction * vertical_loads(
            state.feet[:, :2], com_target, self.mass * GRAVITY, 0.0
        )
        if self.roll_model is not None:
            # damp the deck's roll mode through the trunk's reaction (see the module docstring)
            lateral = state.feet[:, 1] - state.feet[:, 1].mean()
            loads -= self.gains.roll.damping * self._roll_rate * lateral / (lateral @ lateral)
        loads = np.maximum(loads, self.gains.force.min_load)
        mean_velocity = _row_mean(state.feet_velocity)
        position = np.empty(self.n_motors)
        velocity = np.empty(self.n_motors)
        torque = np.empty(self.n_motors)
        unreachable = 0
        for i, (leg, joints) in enumerate(zip(self.legs.legs, self._leg_joints, strict=True)):
            q_leg, reachable = leg.inverse(rotation.T @ (feet[i] - origin), state.q[joints])
            unreachable += not reachable
            position[joints] = q_leg
            relative = state.feet_velocity[i] - mean_velocity - origin_rate
            velocity[joints] = _leg_solve(state.jacobians[i], rotation.T @ relative)
            ground_force_b = state.trunk_rotation[2] * loads[i]  # R_FB^T (0, 0, f_i)
            torque[joints] = state.leg_gravity[joints] - state.jacobians[i].T @ ground_force_b

        joint_gains = self.gains.joints
        share = np.clip(
            4.0 * loads / (self.mass * GRAVITY),
            joint_gains.abad_scale_min,
            joint_gains.abad_scale_max,
        )
        kp, kd = self._kp.copy(), self._kd.copy()
        kp[self._abad] *= share
        kd[self._abad] *= share
        com_f = state.trunk_origin + state.trunk_rotation @ state.com
        self._diagnostics.update(
            deck_roll=state.deck.roll,
            deck_roll_rate=state.deck.roll_rate,
            shift=shift,
            com_y=float(com_f[1] - deck_point[1]),
            unreachable_feet=float(unreachable),
        )
        return MotorCommand(torque=torque, position=position, velocity=velocity, kp=kp, kd=kd)

    def estimate(self) -> EstimatedState | None:
        return self.estimator.state

    def diagnostics(self) -> dict[str, float]:
        return dict(self._diagnostics)
