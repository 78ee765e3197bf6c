"""The base's orientation and angular velocity from an IMU mounted off the base origin.

The IMU sits at a site of the description, placed in the base frame by
:math:`(r_{BS}, R_{BS})` (read from the Pinocchio model of the same MJCF, never from the
simulator). It reports the site's orientation :math:`R_{WS}`, its angular velocity
:math:`\\omega_S` [rad/s] and its specific force :math:`f_S = R_{WS}^\\top(\\ddot p_S - g)`
[m/s^2], all in the site frame. The base then has

.. math::

    R_{WB} = R_{WS} R_{BS}^\\top, \\qquad \\omega_B = R_{BS}\\, \\omega_S,

and the site point's world acceleration is :math:`\\ddot p_S = R_{WS} f_S + g`, exactly (no
lever-arm term, because it is the acceleration of the point the IMU sits at).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.gravity import GRAVITY_WORLD as GRAVITY
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.rotations import matrix_to_quaternion

__all__ = ["GRAVITY", "BaseAttitude", "ImuMount"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class BaseAttitude:
    """The base's orientation and angular velocity, and the IMU point's acceleration.

    Attributes:
        quaternion: :math:`R_{WB}` as (w, x, y, z).
        rotation: :math:`R_{WB}` [3 x 3].
        angular_velocity: :math:`\\omega_B` [rad/s], base frame.
        imu_acceleration: :math:`\\ddot p_S` [m/s^2], world frame, gravity removed.
    """

    quaternion: Array
    rotation: Array
    angular_velocity: Array
    imu_acceleration: Array


@dataclass(frozen=True)
class ImuMount:
    """Where the IMU sits on the base.

    Attributes:
        position: :math:`r_{BS}` [m], the IMU point in the base frame.
        rotation: :math:`R_{BS}` [3 x 3], IMU axes in the base frame.
    """

    position: Array
    rotation: Array

    @classmethod
    def from_pinocchio(cls, pinocchio: PinocchioRobot, site: str) -> ImuMount:
        """Read the IMU site's placement from the description (its Pinocchio frame).

        Raises:
            ConfigError: The model has no frame ``site``, or it is not fixed to the base.
        """
        frame = pinocchio.model.frames[pinocchio.frame_id(site)]
        if frame.parentJoint != 1:  # joint 1 is the free joint (build_pinocchio_robot checks)
            joint = pinocchio.model.names[frame.parentJoint]
            raise ConfigError(f"IMU site '{site}' moves with joint '{joint}', not with the base")
        placement = frame.placement
        return cls(position=np.array(placement.translation), rotation=np.array(placement.rotation))

    def attitude(
        self, quaternion: Array, angular_velocity: Array, specific_force: Array
    ) -> BaseAttitude:
        """The base's attitude from one IMU reading (site frame).

        Args:
            quaternion: :math:`R_{WS}` as (w, x, y, z).
            angular_velocity: :math:`\\omega_S` [rad/s].
            specific_force: :math:`f_S` [m/s^2].
        """
        quaternion_wb = np.empty(4)
        mujoco.mju_mulQuat(quaternion_wb, np.asarray(quaternion, dtype=float), self._inverse)
        mujoco.mju_normalize4(quaternion_wb)
        if quaternion_wb[0] < 0.0:
            quaternion_wb = -quaternion_wb
        flat = np.empty(9)
        mujoco.mju_quat2Mat(flat, quaternion_wb)
        rotation_wb = flat.reshape(3, 3)
        return BaseAttitude(
            quaternion=quaternion_wb,
            rotation=rotation_wb,
            angular_velocity=self.rotation @ angular_velocity,
            imu_acceleration=rotation_wb @ (self.rotation @ specific_force) + GRAVITY,
        )

    @cached_property
    def _inverse(self) -> Array:
        """:math:`R_{BS}^\\top` as a quaternion (w, x, y, z)."""
        quaternion = matrix_to_quaternion(self.rotation)
        quaternion[1:] *= -1.0
        return quaternion
