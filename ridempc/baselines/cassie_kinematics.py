"""Cassie's kinematics for the PD baselines: sensors to centre of mass, feet and virtual legs.

Everything is read from the one description (``robots/cassie/cassie.xml``) through Pinocchio.
A configuration is built from a :class:`~ridempc.sim.sensors.SensorPacket` alone: the base
sits at the origin with the IMU's orientation, the encoded joints (motors, shin and tarsus)
take their encoder readings, and the two joints without encoders (achilles-rod ball and
heel spring) keep their standing-keyframe values, which moves the centre of mass by less than
0.1 mm over the standing range.

Positions are expressed in the **heading frame** H: origin at the pelvis, axes of the world
turned by the pelvis yaw, so x is forward and z is up whatever the pelvis roll and pitch.

The **virtual leg** (Segway paper, Fig. 3b) runs from the hip-pitch joint to the toe joint
("the top of the foot"). In the hip-yaw frame Y, where the hip-pitch axis is :math:`-y`,
with :math:`v = R_{WY}^\\top (p_{toe} - p_{hip})`:

.. math:: L = \\sqrt{v_x^2 + v_z^2}, \\qquad \\theta = \\operatorname{atan2}(v_x, -v_z)

[m], [rad]: the leg length and the relative leg angle (positive with the foot forward of the
hip). The hip pitch turns the leg rigidly, so :math:`\\theta = q_{hp} + \\theta_0(q_{knee})`
and :math:`L = L(q_{knee})`. For targets the springs are taken at rest and the tarsus follows
the knee through the achilles four-bar, eq. (3) of the Segway paper:

.. math:: q_{shin} = 0, \\qquad q_{tarsus} = 13^\\circ - q_{knee}.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.robots.pinocchio_model import PinocchioRobot, build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.rotations import quaternion_to_matrix, rotation_z, rpy_of_matrix

__all__ = [
    "SIDES",
    "TARSUS_OFFSET",
    "CassieKinematics",
    "KinematicState",
    "LegIndices",
    "VirtualLeg",
]

Array = NDArray[np.float64]

SIDES: tuple[str, str] = ("left", "right")
TARSUS_OFFSET: float = np.radians(13.0)  # [rad] eq. (3): tarsus = 13 deg - knee, springs at rest
LEG_MOTORS: tuple[str, ...] = ("hip_roll", "hip_yaw", "hip_pitch", "knee", "toe")


@dataclass(frozen=True)
class LegIndices:
    """Where one leg's joints and frames are.

    Attributes:
        motors: Actuator indices of hip roll, hip yaw, hip pitch, knee, toe.
        q: Pinocchio configuration indices of hip roll, hip yaw, hip pitch, knee, toe,
            shin, tarsus.
        v: Pinocchio velocity indices, same order.
        hip_yaw_frame: Frame of the hip-yaw body (its axes define the leg plane).
        hip_pitch_frame: Frame of the hip-pitch joint (the virtual leg's upper end).
        foot_frame: Frame of the foot body, at the toe joint (the virtual leg's lower end).
        contact_frames: Front and back contact sites of the foot.
        heel_spring_q: Configuration index of the heel spring (no encoder).
    """

    motors: tuple[int, ...]
    q: tuple[int, ...]
    v: tuple[int, ...]
    hip_yaw_frame: int
    hip_pitch_frame: int
    foot_frame: int
    contact_frames: tuple[int, int]
    heel_spring_q: int

    # positions in ``q`` / ``v`` of the named joints
    HIP_ROLL = 0
    HIP_YAW = 1
    HIP_PITCH = 2
    KNEE = 3
    TOE = 4
    SHIN = 5
    TARSUS = 6


@dataclass(frozen=True)
class KinematicState:
    """What the baselines read from one sensor packet, in the heading frame H.

    Attributes:
        time: Sensor time [s].
        rotation: Pelvis orientation :math:`R_{WB}` from the IMU.
        roll: Pelvis roll [rad] (z-y-x Euler angles).
        pitch: Pelvis pitch [rad], positive nose down.
        yaw: Pelvis yaw [rad].
        angular_velocity: Pelvis angular velocity in H [rad/s].
        com: Centre of mass relative to the pelvis [m].
        com_velocity: Centre-of-mass velocity relative to the mean contact point [m/s].
        contacts: Contact sites (left front, left back, right front, right back) [m], 4 x 3.
        support_centre: Mean of the contact sites [m].
        leg_length: Virtual leg length per side (left, right) [m].
        leg_angle: Relative virtual leg angle per side [rad].
        motor_position: Encoder positions of the motors, actuator order [rad].
        motor_velocity: Encoder velocities of the motors [rad/s].
        q: The Pinocchio configuration built from the packet.
    """

    time: float
    rotation: Array
    roll: float
    pitch: float
    yaw: float
    angular_velocity: Array
    com: Array
    com_velocity: Array
    contacts: Array
    support_centre: Array
    leg_length: Array
    leg_angle: Array
    motor_position: Array
    motor_velocity: Array
    q: Array

    @property
    def com_offset(self) -> Array:
        """Centre of mass relative to the support centre [m]."""
        return self.com - self.support_centre


@dataclass(frozen=True)
class VirtualLeg:
    """The rigid virtual leg of one side (springs at rest, eq. 3) tabulated over the knee.

    :math:`L(q_{knee})` is monotonic over the knee's range, so the inverse kinematics is an
    interpolation: :math:`q_{knee} = L^{-1}(L^*)`, :math:`q_{hp} = \\theta^* - \\theta_0(q_{knee})`.
    The table is built from :meth:`CassieKinematics.leg_coordinates` and
    :meth:`CassieKinematics.leg_jacobian` on a grid fine enough that linear interpolation is
    exact to a few 1e-7 m.

    Attributes:
        knee: Knee grid [rad], increasing.
        length: :math:`L` at the grid [m].
        angle0: :math:`\\theta_0 = \\theta - q_{hp}` at the grid [rad].
        d_length: :math:`dL/dq_{knee}` [m/rad].
        d_angle0: :math:`d\\theta_0/dq_{knee}` [-].
    """

    knee: Array
    length: Array
    angle0: Array
    d_length: Array
    d_angle0: Array

    def _by_length(self) -> tuple[Array, Array]:
        if self.length[-1] > self.length[0]:
            return self.length, self.knee
        return self.length[::-1], self.knee[::-1]

    def forward(self, hip_pitch: float, knee: float) -> tuple[float, float]:
        """(L [m], theta [rad]) of the joint angles."""
        length = float(np.interp(knee, self.knee, self.length))
        return length, hip_pitch + float(np.interp(knee, self.knee, self.angle0))

    def jacobian(self, knee: float) -> Array:
        """:math:`\\partial (L, \\theta) / \\partial (q_{hp}, q_{knee})` [2 x 2]."""
        return np.array(
            [
                [0.0, float(np.interp(knee, self.knee, self.d_length))],
                [1.0, float(np.interp(knee, self.knee, self.d_angle0))],
            ]
        )

    def inverse(self, length: float, angle: float) -> tuple[float, float]:
        """(hip pitch, knee) [rad] of the virtual leg (``length`` [m], ``angle`` [rad]).

        A length outside the table is clamped to its ends (the knee's joint range).
        """
        lengths, knees = self._by_length()
        knee = float(np.interp(length, lengths, knees))
        return angle - float(np.interp(knee, self.knee, self.angle0)), knee


class CassieKinematics:
    """Cassie's kinematics from the MJCF description, evaluated on sensor packets.

    Args:
        robot: The Cassie robot (its description and encoder list).

    Raises:
        ConfigError: The robot lacks a joint, frame or encoder these kinematics need.
    """

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.pinocchio: PinocchioRobot = build_pinocchio_robot(robot)
        model = self.pinocchio.model
        self.model = model
        self._data = model.createData()
        self._leg_data = model.createData()
        self.mass = float(sum(inertia.mass for inertia in model.inertias))
        self.gravity = float(np.linalg.norm(model.gravity.linear))
        template = self.pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
        template[:3] = 0.0
        template[3:7] = (0.0, 0.0, 0.0, 1.0)
        self._template = template
        encoders = robot.encoder_joints
        motors = [m.joint for m in robot.motors]
        self.legs = {side: self._leg(side, motors, encoders) for side in SIDES}
        self._encoder_q = np.array([self._joint(name).idx_q for name in encoders])
        self._encoder_v = np.array([self._joint(name).idx_v for name in encoders])
        self._motor_encoder = np.array([encoders.index(j) for j in motors])
        imu = self._frame(robot.params.imu_site, pin.FrameType.OP_FRAME)
        self._imu_to_base = model.frames[imu].placement.rotation.copy()

    # ------------------------------------------------------------------ lookup

    def _joint(self, name: str) -> pin.JointModel:
        if not self.model.existJointName(name):
            raise ConfigError(f"Cassie kinematics: robot '{self.robot.name}' has no joint '{name}'")
        return self.model.joints[self.model.getJointId(name)]

    def _frame(self, name: str, kind: pin.FrameType) -> int:
        if not self.model.existFrame(name, kind):
            raise ConfigError(
                f"Cassie kinematics: robot '{self.robot.name}' has no {kind} frame '{name}'"
            )
        return int(self.model.getFrameId(name, kind))

    def _leg(self, side: str, motors: list[str], encoders: tuple[str, ...]) -> LegIndices:
        names = [f"{side}_{j}" for j in (*LEG_MOTORS, "shin", "tarsus")]
        joints = [self._joint(name) for name in names]
        for name in names:
            if name not in encoders:
                raise ConfigError(f"Cassie kinematics: joint '{name}' needs an encoder")
        for name in names[:5]:
            if name not in motors:
                raise ConfigError(f"Cassie kinematics: joint '{name}' needs a motor")
        return LegIndices(
            motors=tuple(motors.index(n) for n in names[:5]),
            q=tuple(j.idx_q for j in joints),
            v=tuple(j.idx_v for j in joints),
            hip_yaw_frame=self._frame(f"{side}_hip_yaw", pin.FrameType.BODY),
            hip_pitch_frame=self._frame(f"{side}_hip_pitch", pin.FrameType.JOINT),
            foot_frame=self._frame(f"{side}_foot", pin.FrameType.BODY),
            heel_spring_q=self._joint(f"{side}_heel_spring").idx_q,
            contact_frames=(
                self._frame(f"{side}_toe_front", pin.FrameType.OP_FRAME),
                self._frame(f"{side}_toe_back", pin.FrameType.OP_FRAME),
            ),
        )

    # ---------------------------------------------------------- configuration

    def base_rotation(self, imu_quaternion: Array) -> Array:
        """Pelvis orientation :math:`R_{WB}` from the IMU quaternion (w, x, y, z)."""
        return quaternion_to_matrix(imu_quaternion) @ self._imu_to_base.T

    def configuration(self, rotation: Array, joint_position: Array) -> Array:
        """Pinocchio configuration: base at the origin with ``rotation``, encoded joints set.

        Args:
            rotation: Pelvis orientation :math:`R_{WB}`.
            joint_position: Encoder positions, ordered as ``robot.encoder_joints`` [rad].
        """
        q = self._template.copy()
        q[3:7] = pin.Quaternion(rotation).normalized().coeffs()
        q[self._encoder_q] = joint_position
        return q

    def velocity(self, angular_velocity: Array, joint_velocity: Array) -> Array:
        """Pinocchio velocity: base linear velocity zero, base angular velocity [rad/s] in the
        pelvis frame, encoded joints from their encoders, other joints zero."""
        v = np.zeros(self.model.nv)
        v[3:6] = angular_velocity
        v[self._encoder_v] = joint_velocity
        return v

    # ------------------------------------------------------------ measurement

    def measure(
        self,
        time: float,
        imu_quaternion: Array,
        gyro: Array,
        joint_position: Array,
        joint_velocity: Array,
    ) -> KinematicState:
        """The kinematic state from one packet's IMU and encoders.

        Args:
            time: Sensor time [s].
            imu_quaternion: IMU orientation (w, x, y, z).
            gyro: IMU angular velocity in the IMU frame [rad/s].
            joint_position: Encoder positions [rad], ``robot.encoder_joints`` order.
            joint_velocity: Encoder velocities [rad/s].
        """
        model, data = self.model, self._data
        rotation = self.base_rotation(imu_quaternion)
        omega_base = self._imu_to_base @ np.asarray(gyro, dtype=float)
        q = self.configuration(rotation, joint_position)
        v = self.velocity(omega_base, joint_velocity)
        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        com_world = pin.centerOfMass(model, data, q, v, False)
        vcom_world = np.array(data.vcom[0])
        roll, pitch, yaw = rpy_of_matrix(rotation)
        heading = rotation_z(yaw).T  # world-aligned -> heading frame
        contacts = np.empty((4, 3))
        contact_velocity = np.zeros(3)
        lengths = np.empty(2)
        angles = np.empty(2)
        for i, side in enumerate(SIDES):
            leg = self.legs[side]
            for j, frame in enumerate(leg.contact_frames):
                contacts[2 * i + j] = heading @ data.oMf[frame].translation
                velocity = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
                contact_velocity += velocity.linear / 4.0
            lengths[i], angles[i] = self._leg_coordinates(data, leg)
        support = contacts.mean(axis=0)
        return KinematicState(
            time=time,
            rotation=rotation,
            roll=roll,
            pitch=pitch,
            yaw=yaw,
            angular_velocity=heading @ rotation @ omega_base,
            com=heading @ com_world,
            com_velocity=heading @ (vcom_world - contact_velocity),
            contacts=contacts,
            support_centre=support,
            leg_length=lengths,
            leg_angle=angles,
            motor_position=np.asarray(joint_position)[self._motor_encoder],
            motor_velocity=np.asarray(joint_velocity)[self._motor_encoder],
            q=q,
        )

    # ------------------------------------------------------------ virtual leg

    def _leg_vector(self, data: pin.Data, leg: LegIndices) -> Array:
        """Hip-pitch joint to toe joint in the hip-yaw frame [m] (placements must be fresh)."""
        hip = data.oMf[leg.hip_pitch_frame].translation
        toe = data.oMf[leg.foot_frame].translation
        return np.asarray(data.oMf[leg.hip_yaw_frame].rotation.T @ (toe - hip))

    def _leg_coordinates(self, data: pin.Data, leg: LegIndices) -> tuple[float, float]:
        v = self._leg_vector(data, leg)
        return float(np.hypot(v[0], v[2])), float(np.arctan2(v[0], -v[2]))

    def rigid_leg(self, side: str, hip_pitch: float, knee: float) -> tuple[pin.Data, Array]:
        """Forward kinematics of one leg with the springs (shin, heel) at rest and the tarsus by
        eq. (3); returns its own data (frame placements fresh) and configuration."""
        leg = self.legs[side]
        q = self._template.copy()
        q[leg.q[LegIndices.HIP_PITCH]] = hip_pitch
        q[leg.q[LegIndices.KNEE]] = knee
        q[leg.q[LegIndices.SHIN]] = 0.0
        q[leg.q[LegIndices.TARSUS]] = TARSUS_OFFSET - knee
        q[leg.heel_spring_q] = 0.0
        data = self._leg_data
        pin.forwardKinematics(self.model, data, q)
        pin.updateFramePlacements(self.model, data)
        return data, q

    def leg_coordinates(self, side: str, hip_pitch: float, knee: float) -> Array:
        """Virtual leg (L [m], theta [rad]) of a rigid leg (springs at rest, eq. 3)."""
        data, _ = self.rigid_leg(side, hip_pitch, knee)
        return np.array(self._leg_coordinates(data, self.legs[side]))

    def leg_jacobian(self, side: str, hip_pitch: float, knee: float) -> Array:
        """:math:`\\partial (L, \\theta) / \\partial (q_{hp}, q_{knee})` of a rigid leg [2 x 2].

        The knee column includes the tarsus it drives through the four-bar (eq. 3),
        :math:`\\partial q_{tarsus} / \\partial q_{knee} = -1`:

        .. math:: \\frac{\\partial L}{\\partial q} = \\frac{v_x \\dot v_x + v_z \\dot v_z}{L},
            \\qquad \\frac{\\partial \\theta}{\\partial q} =
            \\frac{-v_z \\dot v_x + v_x \\dot v_z}{L^2}.
        """
        leg = self.legs[side]
        data, q = self.rigid_leg(side, hip_pitch, knee)
        pin.computeJointJacobians(self.model, data, q)
        jac = pin.getFrameJacobian(self.model, data, leg.foot_frame, pin.LOCAL_WORLD_ALIGNED)
        axes = data.oMf[leg.hip_yaw_frame].rotation
        columns = jac[:3, [leg.v[LegIndices.HIP_PITCH], leg.v[LegIndices.KNEE]]]
        columns[:, 1] -= jac[:3, leg.v[LegIndices.TARSUS]]
        dv = axes.T @ columns  # the hip-pitch joint origin does not move with these joints
        v = self._leg_vector(data, leg)
        length_sq = v[0] ** 2 + v[2] ** 2
        d_length = (v[0] * dv[0] + v[2] * dv[2]) / np.sqrt(length_sq)
        d_angle = (-v[2] * dv[0] + v[0] * dv[2]) / length_sq
        return np.vstack([d_length, d_angle])

    def virtual_leg(self, side: str, step: float = 1e-3) -> VirtualLeg:
        """Tabulate the rigid virtual leg of ``side`` over the knee's joint range."""
        joint = self.model.joints[self.model.getJointId(f"{side}_knee")]
        low = float(self.model.lowerPositionLimit[joint.idx_q])
        high = float(self.model.upperPositionLimit[joint.idx_q])
        knees = np.linspace(low, high, int(np.ceil((high - low) / step)) + 1)
        rows = []
        for knee in knees:
            length, angle = self.leg_coordinates(side, 0.0, knee)
            jac = self.leg_jacobian(side, 0.0, knee)
            rows.append((length, angle, jac[0, 1], jac[1, 1]))
        table = np.array(rows)
        return VirtualLeg(knees, table[:, 0], table[:, 1], table[:, 2], table[:, 3])
