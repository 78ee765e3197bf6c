"""Rotation helpers on (w, x, y, z) quaternions and rotation matrices, in NumPy.

Conventions: a quaternion or matrix maps a vector from a body frame to the world,
:math:`v_W = R_{WB} v_B`; Euler angles are z-y-x (yaw, pitch, roll),
:math:`R = R_z(\\psi) R_y(\\theta) R_x(\\phi)`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "matrix_of_rpy",
    "matrix_to_quaternion",
    "quaternion_to_matrix",
    "rpy_of_matrix",
    "wrap_angle",
    "yaw_of",
]

Array = NDArray[np.float64]


def quaternion_to_matrix(quat_wxyz: Array) -> Array:
    """:math:`R(q)` for a unit quaternion (w, x, y, z) [3 x 3]."""
    w, x, y, z = quat_wxyz / np.linalg.norm(quat_wxyz)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quaternion(rotation: Array) -> Array:
    """Unit quaternion (w, x, y, z) with non-negative w of a rotation matrix."""
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * np.sqrt(1.0 + trace)
        quat = np.array(
            [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
        )
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        quat = np.empty(4)
        quat[0] = (m[k, j] - m[j, k]) / s
        quat[1 + i] = 0.25 * s
        quat[1 + j] = (m[j, i] + m[i, j]) / s
        quat[1 + k] = (m[k, i] + m[i, k]) / s
    quat /= math.sqrt(quat.dot(quat))  # np.linalg.norm's sum, without its wrapper
    return quat if quat[0] >= 0.0 else -quat


def wrap_angle(angle: float) -> float:
    """``angle`` [rad] wrapped into :math:`[-\\pi, \\pi)`."""
    return float((angle + math.pi) % (2.0 * math.pi) - math.pi)


def yaw_of(quat_wxyz: Array) -> float:
    """Heading :math:`\\psi` of the body's x axis [rad]."""
    w, x, y, z = quat_wxyz
    return float(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def rpy_of_matrix(rotation: Array) -> tuple[float, float, float]:
    """Roll, pitch, yaw [rad] of :math:`R = R_z(\\psi) R_y(\\theta) R_x(\\phi)`."""
    roll = float(np.arctan2(rotation[2, 1], rotation[2, 2]))
    pitch = float(-np.arcsin(min(max(rotation[2, 0], -1.0), 1.0)))  # np.clip: 5 us a scalar
    yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
    return roll, pitch, yaw


def matrix_of_rpy(roll: float, pitch: float, yaw: float) -> Array:
    """:math:`R = R_z(\\psi) R_y(\\theta) R_x(\\phi)` of roll, pitch, yaw [rad]: NumPy's twin
    of :func:`ridempc.trajopt.rotations.euler_zyx_matrix`, which would bring CasADi into
    the estimator."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )
