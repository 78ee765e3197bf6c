"""Analytic kinematics of a quadruped's abad-hip-knee legs, read from the robot's description.

Each leg is a chain trunk → abad (revolute about the trunk's x) → hip (about y) → knee
(about y) → foot centre, with the offsets of the description's joint placements:

.. math:: p(q) = h + R_x(q_1)\\big(a + R_y(q_2)\\,(t + R_y(q_3)\\, s)\\big)

[m, trunk frame], where :math:`h` is the abad joint's position in the trunk, :math:`a` the
abad-to-hip offset (purely lateral), :math:`t` the hip-to-knee offset (thigh) and :math:`s`
the knee-to-foot offset (shank), both in the leg's sagittal x-z plane. The numbers come from
the Pinocchio model of the same MJCF the simulation runs (CyberDog2: :math:`h = (\\pm 0.164,
\\pm 0.042, 0)`, :math:`a = (0, \\pm 0.094, 0)`, :math:`t = (0, 0, -0.12)`,
:math:`s = (0.0055, 0, -0.17391)`).

The inverse kinematics is closed form. Writing a vector :math:`(x, z)` of the sagittal plane
as the complex number :math:`z + i x`, a rotation about y by :math:`\\theta` multiplies it by
:math:`e^{i\\theta}`, so with the foot at :math:`(x', z')` in the hip frame

.. math:: |t + e^{i q_3} s|^2 = |t|^2 + |s|^2 + 2|t||s|\\cos(q_3 + \\arg s - \\arg t)
          = x'^2 + z'^2, \\qquad q_2 = \\arg(z' + i x') - \\arg(t + e^{i q_3} s)

and the abad angle from the lateral plane: :math:`(p_y, p_z) - (h_y, h_z)` has length
:math:`\\sqrt{a_y^2 + z'^2}` and :math:`q_1 = \\operatorname{atan2}(p_z, p_y) -
\\operatorname{atan2}(z', a_y)`. The knee branch and the sign of :math:`z'` (foot below the
hip) are taken from a reference configuration.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.rotations import wrap_angle

__all__ = ["LegKinematics", "QuadrupedLegs"]

Array = NDArray[np.float64]
STRUCTURE_TOLERANCE: float = 1e-9  # [m] offsets that must vanish for the closed-form IK


def _sagittal(vector: Array) -> complex:
    """A vector of the x-z plane as the complex number :math:`z + i x`."""
    return complex(vector[2], vector[0])


@dataclass(frozen=True)
class LegKinematics:
    """One leg's closed-form kinematics.

    Attributes:
        name: The leg's contact frame (e.g. ``FL_contact``).
        hip: Abad joint position in the trunk frame :math:`h` [m].
        abad_to_hip: Abad-to-hip offset :math:`a` (only y non-zero) [m].
        thigh: Hip-to-knee offset :math:`t` (y zero) [m].
        shank: Knee-to-foot-centre offset :math:`s` (y zero) [m].
        motors: Indices of the abad, hip and knee motors in actuator order.
    """

    name: str
    hip: Array
    abad_to_hip: Array
    thigh: Array
    shank: Array
    motors: tuple[int, int, int]

    def position_and_jacobian(self, q: Array) -> tuple[Array, Array]:
        """Foot centre :math:`p(q)` in the trunk frame [m] and :math:`J = \\partial p /
        \\partial q` [m/rad] (3 x 3), for ``q`` = (abad, hip, knee) [rad]."""
        c1, s1 = math.cos(q[0]), math.sin(q[0])
        c2, s2 = math.cos(q[1]), math.sin(q[1])
        c3, s3 = math.cos(q[2]), math.sin(q[2])
        sx, sz = self.shank[0], self.shank[2]
        shank_x, shank_z = sx * c3 + sz * s3, -sx * s3 + sz * c3  # R_y(q3) s
        v3x, v3z = self.thigh[0] + shank_x, self.thigh[2] + shank_z  # t + R_y(q3) s
        v2x, v2z = v3x * c2 + v3z * s2, -v3x * s2 + v3z * c2  # R_y(q2) (...)
        wy = self.abad_to_hip[1]
        position = np.array(
            [
                self.hip[0] + v2x,
                self.hip[1] + wy * c1 - v2z * s1,
                self.hip[2] + wy * s1 + v2z * c1,
            ]
        )
        d2x, d2z = shank_z * c2 - shank_x * s2, -shank_z * s2 - shank_x * c2  # R_y(q2) dR_y(q3) s
        jacobian = np.array(
            [
                [0.0, v2z, d2x],
                [-wy * s1 - v2z * c1, v2x * s1, -d2z * s1],
                [wy * c1 - v2z * s1, -v2x * c1, d2z * c1],
            ]
        )
        return position, jacobian

    def position(self, q: Array) -> Array:
        """Foot centre in the trunk frame, :math:`p(q)` [m], for ``q`` = (abad, hip, knee)."""
        return self.position_and_jacobian(q)[0]

    def jacobian(self, q: Array) -> Array:
        """:math:`\\partial p / \\partial q` [m/rad], 3 x 3."""
        return self.position_and_jacobian(q)[1]

    def inverse(self, foot: Array, reference: Array) -> tuple[Array, bool]:
        """Joint angles that put the foot centre at ``foot`` (trunk frame) [rad].

        Args:
            foot: Wanted foot centre in the trunk frame [m].
            reference: A nearby configuration: it picks the knee branch and which side of
                the hip the foot is on.

        Returns:
            The angles (abad, hip, knee) and whether ``foot`` was reachable; an unreachable
            foot gets the nearest stretched or folded leg.
        """
        reachable = True
        rx, ry, rz = foot[0] - self.hip[0], foot[1] - self.hip[1], foot[2] - self.hip[2]
        lateral = float(self.abad_to_hip[1])
        t, s = self._thigh_c, self._shank_c
        reference_sagittal = cmath.exp(1j * reference[1]) * (t + cmath.exp(1j * reference[2]) * s)
        below = -1.0 if reference_sagittal.real <= 0.0 else 1.0
        plane_sq = ry * ry + rz * rz - lateral * lateral
        if plane_sq < 0.0:
            reachable, plane_sq = False, 0.0
        z_hip = below * math.sqrt(plane_sq)
        q1 = math.atan2(rz, ry) - math.atan2(z_hip, lateral)
        target = complex(z_hip, rx)
        cos_knee = (abs(target) ** 2 - abs(t) ** 2 - abs(s) ** 2) / (2.0 * abs(t) * abs(s))
        if not -1.0 <= cos_knee <= 1.0:
            reachable, cos_knee = False, min(1.0, max(-1.0, cos_knee))
        offset = cmath.phase(s) - cmath.phase(t)
        branch = 1.0 if wrap_angle(reference[2] + offset) >= 0.0 else -1.0
        q3 = branch * math.acos(cos_knee) - offset
        q2 = cmath.phase(target) - cmath.phase(t + cmath.exp(1j * q3) * s)
        return np.array([wrap_angle(q1), wrap_angle(q2), wrap_angle(q3)]), reachable

    @property
    def _thigh_c(self) -> complex:
        return _sagittal(self.thigh)

    @property
    def _shank_c(self) -> complex:
        return _sagittal(self.shank)


class QuadrupedLegs:
    """The four legs of a quadruped, read from its Pinocchio model.

    Args:
        robot: Pinocchio's reading of the description.
        contact_frames: The feet's contact frames (foot centres), in leg order.
        motor_joints: The motor joints in actuator order.

    Raises:
        ConfigError: A leg is not an abad (x) - hip (y) - knee (y) chain from the trunk with
            the offsets the closed form needs.
    """

    def __init__(
        self, robot: PinocchioRobot, contact_frames: tuple[str, ...], motor_joints: tuple[str, ...]
    ) -> None:
        model = robot.model
        legs = []
        for frame_name in contact_frames:
            frame = model.frames[robot.frame_id(frame_name)]
            chain: list[int] = []
            joint = int(frame.parentJoint)
            while joint > 0 and len(chain) < 4:
                chain.append(joint)
                joint = int(model.parents[joint])
            chain.reverse()  # trunk first
            kinds = [model.joints[j].shortname() for j in chain]
            if kinds != ["JointModelFreeFlyer", "JointModelRX", "JointModelRY", "JointModelRY"]:
                raise ConfigError(
                    f"{model.name}: leg of '{frame_name}' is {kinds[1:]}, "
                    "expected an abad (RX) - hip (RY) - knee (RY) chain from the trunk"
                )
            _, abad, hip, knee = chain
            for j in (abad, hip, knee):
                if not np.allclose(model.jointPlacements[j].rotation, np.eye(3)):
                    raise ConfigError(f"{model.name}: joint '{model.names[j]}' is rotated")
            if not np.allclose(frame.placement.rotation, np.eye(3)):
                raise ConfigError(f"{model.name}: frame '{frame_name}' is rotated")
            offset = np.array(model.jointPlacements[hip].translation)
            thigh = np.array(model.jointPlacements[knee].translation)
            shank = np.array(frame.placement.translation)
            if (
                abs(offset[0]) > STRUCTURE_TOLERANCE
                or abs(offset[2]) > STRUCTURE_TOLERANCE
                or abs(thigh[1]) > STRUCTURE_TOLERANCE
                or abs(shank[1]) > STRUCTURE_TOLERANCE
            ):
                raise ConfigError(
                    f"{model.name}: leg of '{frame_name}' has offsets the closed-form "
                    "kinematics cannot take (abad-to-hip must be lateral, thigh and shank sagittal)"
                )
            names = [model.names[j] for j in (abad, hip, knee)]
            missing = [n for n in names if n not in motor_joints]
            if missing:
                raise ConfigError(f"{model.name}: joint '{missing[0]}' has no motor")
            legs.append(
                LegKinematics(
                    name=frame_name,
                    hip=np.array(model.jointPlacements[abad].translation),
                    abad_to_hip=offset,
                    thigh=thigh,
                    shank=shank,
                    motors=(
                        motor_joints.index(names[0]),
                        motor_joints.index(names[1]),
                        motor_joints.index(names[2]),
                    ),
                )
            )
        self.legs: tuple[LegKinematics, ...] = tuple(legs)
        self._model = model
        self._data = model.createData()
        self._q = pin.neutral(model)
        self._motor_q = np.array([model.joints[model.getJointId(n)].idx_q for n in motor_joints])
        self._motor_v = np.array([model.joints[model.getJointId(n)].idx_v for n in motor_joints])

    def positions(self, q_motors: Array) -> Array:
        """Foot centres in the trunk frame, shape (4, 3) [m], from the motor angles."""
        return np.array([leg.position(q_motors[list(leg.motors)]) for leg in self.legs])

    def com_and_gravity(self, q_motors: Array, trunk_rotation: Array) -> tuple[Array, Array]:
        """The centre of mass and the legs' own gravity torques (Pinocchio).

        Args:
            q_motors: Motor angles in actuator order [rad].
            trunk_rotation: The trunk's orientation in a gravity-aligned frame.

        Returns:
            The whole robot's centre of mass in the trunk frame [m], and per motor the
            torque that holds the links beyond it against gravity, :math:`g(q)` [N m].
        """
        self._q[3:7] = pin.Quaternion(trunk_rotation).coeffs()
        self._q[self._motor_q] = q_motors
        gravity = pin.computeGeneralizedGravity(self._model, self._data, self._q)
        com = pin.centerOfMass(self._model, self._data, self._q)
        return trunk_rotation.T @ com, np.array(gravity[self._motor_v])
