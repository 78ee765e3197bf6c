"""Z-Y-X Euler angles, the attitude coordinates of the skateboard paper's eq. (1)-(3).

:math:`\\theta = (\\phi, \\vartheta, \\psi)` (roll, pitch, yaw) with
:math:`R = R_z(\\psi) R_y(\\vartheta) R_x(\\phi)`, body frame to world. The rate map
:math:`T(\\theta)` of eq. (3) turns the body-frame angular velocity into Euler-angle rates,
:math:`\\dot\\theta = T(\\theta)\\,\\omega`.

Every function takes an ``xp`` module (:mod:`numpy` or :mod:`casadi`) and uses only
arithmetic and ``xp.sin``/``xp.cos``, so the optimisation and the NumPy validation share it.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import casadi as ca
import numpy as np

__all__ = ["euler_rate_map", "euler_zyx_matrix", "rotation_x", "rotation_z", "stack3x3"]


def stack3x3(rows: list[list[Any]], xp: ModuleType = np) -> Any:
    """A 3 x 3 matrix from nested rows, as a NumPy array or a CasADi matrix."""
    if xp is ca:
        return ca.vertcat(*[ca.horzcat(*row) for row in rows])
    return np.array(rows, dtype=float)


def rotation_x(angle: Any, xp: ModuleType = np) -> Any:
    """Rotation by ``angle`` [rad] about x."""
    c, s = xp.cos(angle), xp.sin(angle)
    return stack3x3([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]], xp)


def rotation_z(angle: Any, xp: ModuleType = np) -> Any:
    """Rotation by ``angle`` [rad] about z."""
    c, s = xp.cos(angle), xp.sin(angle)
    return stack3x3([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], xp)


def euler_zyx_matrix(roll: Any, pitch: Any, yaw: Any, xp: ModuleType = np) -> Any:
    """:math:`R = R_z(\\psi) R_y(\\vartheta) R_x(\\phi)` (body to world) for angles in [rad]."""
    cr, sr = xp.cos(roll), xp.sin(roll)
    cp, sp = xp.cos(pitch), xp.sin(pitch)
    cy, sy = xp.cos(yaw), xp.sin(yaw)
    return stack3x3(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ],
        xp,
    )


def euler_rate_map(roll: Any, pitch: Any, xp: ModuleType = np) -> Any:
    """:math:`T(\\theta)` of eq. (3): :math:`\\dot\\theta = T(\\theta)\\,\\omega_{body}`.

    .. math:: T = \\begin{bmatrix} 1 & s_\\phi t_\\vartheta & c_\\phi t_\\vartheta \\\\
                  0 & c_\\phi & -s_\\phi \\\\ 0 & s_\\phi / c_\\vartheta & c_\\phi / c_\\vartheta
                  \\end{bmatrix}

    Singular at :math:`\\vartheta = \\pm\\pi/2`; the optimisation bounds the pitch far from it.
    """
    cr, sr = xp.cos(roll), xp.sin(roll)
    cp, sp = xp.cos(pitch), xp.sin(pitch)
    return stack3x3(
        [
            [1.0, sr * sp / cp, cr * sp / cp],
            [0.0, cr, -sr],
            [0.0, sr / cp, cr / cp],
        ],
        xp,
    )
