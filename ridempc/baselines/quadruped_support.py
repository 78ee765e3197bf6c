"""The support under a quadruped's four feet: the deck's plane and the feet's vertical loads.

**The deck from the feet** (skateboard paper, Sec. V: the board's posture from the robot's own
joint sensors). With all four feet on the deck, the foot centres :math:`p_i` (in a level
frame: gravity-aligned z, yawed with the feet) lie on a plane parallel to the deck's top,

.. math:: z = z_0 + b\\,x + c\\,y

fitted by least squares; its upward normal is :math:`n \\propto (-b, -c, 1)` and, with the
deck's z-y-x Euler angles (:math:`n = R_y(\\theta) R_x(\\varphi)\\,\\hat z =
(\\cos\\varphi \\sin\\theta, -\\sin\\varphi, \\cos\\varphi\\cos\\theta)`),

.. math:: \\varphi = \\operatorname{atan2}\\big(-n_y, \\sqrt{n_x^2 + n_z^2}\\big), \\qquad
          \\dot\\varphi = \\partial \\dot z / \\partial y

(positive roll lowers the right, -y, edge). The rate is the slope of the feet's vertical
velocities across the deck, from the same least squares: feet turning rigidly with the deck
about x move by :math:`\\dot z_i = \\dot\\varphi\\, y_i` exactly, so no angle is
differentiated.

**Vertical loads.** The feedforward weight shares :math:`f_i` [N] are the least-norm solution
of :math:`\\sum f_i = m g`, :math:`\\sum f_i (p_i - c)_{x,y} = 0` (their centre of pressure
under the centre of mass :math:`c`), floored at a minimum load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation.lapack import pinv, solve

__all__ = ["SupportPlane", "fit_support_plane", "vertical_loads"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SupportPlane:
    """The plane through the feet, in the level frame the points were given in.

    Attributes:
        height: :math:`z_0`, the plane's height at the frame's origin [m].
        roll: :math:`\\varphi` [rad], positive with the -y side lower.
        pitch: :math:`\\theta` [rad], positive with the +x side lower.
        roll_rate: :math:`\\dot\\varphi` [rad/s] (zero when no velocities were given).
        normal: Upward unit normal.
    """

    height: float
    roll: float
    pitch: float
    roll_rate: float
    normal: Array


def fit_support_plane(points: Array, velocities: Array | None = None) -> SupportPlane:
    """Least-squares plane :math:`z = z_0 + b x + c y` through ``points`` (n x 3, n >= 3).

    Args:
        points: Foot centres in a level frame [m].
        velocities: Their velocities in the same frame [m/s], for the roll rate.
    """
    design = np.ones((len(points), 3))  # rows (1, x_i, y_i)
    design[:, 1:] = points[:, :2]
    pseudo_inverse = pinv(design)
    z0, b, c = pseudo_inverse @ points[:, 2]
    normal = np.array([-b, -c, 1.0]) / math.sqrt(1.0 + b * b + c * c)
    roll = math.atan2(-normal[1], math.hypot(normal[0], normal[2]))
    pitch = math.atan2(normal[0], normal[2])
    roll_rate = 0.0
    if velocities is not None:
        roll_rate = float((pseudo_inverse @ velocities[:, 2])[2])
    return SupportPlane(float(z0), roll, pitch, roll_rate, normal)


def vertical_loads(feet_xy: Array, com_xy: Array, weight: float, minimum: float) -> Array:
    """Vertical load of each foot [N] with their centre of pressure under ``com_xy``.

    Args:
        feet_xy: Foot positions in a level frame, (n, 2) [m].
        com_xy: Centre of mass in the same frame [m].
        weight: :math:`m g` [N].
        minimum: Floor of each load [N] (a foot never pulls).

    Returns:
        The least-norm loads :math:`f = A^\\top (A A^\\top)^{-1} (m g, 0, 0)` with
        :math:`A = [1;\\ (p_i - c)_x;\\ (p_i - c)_y]`, floored at ``minimum``.
    """
    rel = feet_xy - com_xy
    constraints = np.vstack((np.ones(len(rel)), rel[:, 0], rel[:, 1]))
    wanted = np.array([weight, 0.0, 0.0])
    loads = constraints.T @ solve(constraints @ constraints.T, wanted)
    return np.maximum(loads, minimum)
