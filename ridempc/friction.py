"""The friction pyramid that the planners and controllers put on every contact force.

Coulomb friction :math:`\\mu` lets a contact carry any force :math:`\\phi` (in the surface's
frame) with :math:`\\lVert(\\phi_x, \\phi_y)\\rVert \\le \\mu\\, \\phi_z`: a circular cone. The
trajectory optimisation, the MPC and the whole-body QP use the linear pyramid

.. math:: |\\phi_x| \\le s\\, \\phi_z, \\qquad |\\phi_y| \\le s\\, \\phi_z, \\qquad
          s = \\mu / \\sqrt 2,

the cone's *inner* pyramid: its edges reach :math:`\\lVert(\\phi_x, \\phi_y)\\rVert =
\\mu\\, \\phi_z`, so every force it allows is inside the cone, however its tangent axes are
turned. The outer pyramid (:math:`s = \\mu`) reaches :math:`\\sqrt 2\\, \\mu` along its
diagonals, outside the cone. MuJoCo's own contact (its default pyramidal cone, the four edges
:math:`n \\pm \\mu_{sim} t_k`) is the diamond :math:`|\\phi_x| + |\\phi_y| \\le \\mu_{sim}
\\phi_z`, whose inscribed circle has radius :math:`\\mu_{sim} / \\sqrt 2`: with
:math:`\\mu = 0.6` and the descriptions' :math:`\\mu_{sim} = 1`, the inner pyramid's corner
sums to 0.85, the outer one's to 1.2.

Found on the skateboard: 3 s into push-off-0.7, at the end of its second push, the dog's
pushing foot carried :math:`(\\phi_x, \\phi_y) = (12.4, -12.4)` N on :math:`\\phi_z = 24.9` N
(in a variant of the library that keeps the pusher's knee bent; the committed one let go
alike at 3.02 s), inside the outer pyramid of :math:`\\mu = 0.6` (0.50 of :math:`\\phi_z` each
way) but on MuJoCo's diamond (0.996): the foot slid 6 cm and the dog fell within 0.5 s.

The box is one of two inner pyramids with four faces; the other is the **diamond**

.. math:: |\\phi_x| + |\\phi_y| \\le \\mu\\, \\phi_z,

the box turned by 45 degrees: the same area, its corners on the cone along the tangent
axes. It allows :math:`\\mu` rather than :math:`\\mu/\\sqrt2` along each axis, and half
:math:`\\mu` each way on the diagonals, and with :math:`\\mu = 0.6` it lies inside MuJoCo's
diamond of :math:`\\mu_{sim} = 1` however that one's tangents are turned (inside its
inscribed circle, of radius 0.71). A line foot twists its platform with opposite forces
across the line at its two ends, so its yaw torque grows by :math:`\\sqrt 2` in the
diamond: with it the MPC rider holds a 0.5 rad/s turn on the Hovershoes, where in the box
the shoes' yaw needed more than the feet could twist (:mod:`ridempc.mpc.pairs`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["SHAPES", "pyramid_matrix", "pyramid_rows", "pyramid_slope"]

SHAPES: tuple[str, ...] = ("box", "diamond")


def pyramid_slope(friction: float) -> float:
    """:math:`s = \\mu / \\sqrt 2` [-], the inner pyramid's bound on each tangential force
    over the normal force, for the Coulomb friction coefficient ``friction`` [-]."""
    return friction / math.sqrt(2.0)


def pyramid_rows(local: Any, friction: float, shape: str = "box") -> list[Any]:
    """An inner pyramid's five rows on a force ``local`` = :math:`(\\phi_x, \\phi_y,
    \\phi_z)` in its surface's frame (NumPy or CasADi), each :math:`\\ge 0` inside it:
    the ``box`` :math:`\\phi_z,\\ s\\phi_z \\mp \\phi_x,\\ s\\phi_z \\mp \\phi_y`, or the
    ``diamond`` :math:`\\phi_z,\\ \\mu\\phi_z \\mp \\phi_x \\mp \\phi_y` (in the order
    ``--, -+, +-, ++``; see the module docstring).

    Raises:
        ValueError: An unknown shape.
    """
    if shape == "box":
        s = pyramid_slope(friction)
        return [
            local[2],
            s * local[2] - local[0],
            s * local[2] + local[0],
            s * local[2] - local[1],
            s * local[2] + local[1],
        ]
    if shape == "diamond":
        m = friction
        return [
            local[2],
            m * local[2] - local[0] - local[1],
            m * local[2] - local[0] + local[1],
            m * local[2] + local[0] - local[1],
            m * local[2] + local[0] + local[1],
        ]
    raise ValueError(f"friction pyramid shape '{shape}': expected one of {', '.join(SHAPES)}")


def pyramid_matrix(friction: float, shape: str = "box") -> NDArray[np.float64]:
    """:func:`pyramid_rows` as a 5 x 3 matrix :math:`G`, :math:`G \\phi \\ge 0` inside the
    pyramid (the rows of the identity's columns): for controllers that apply it to many
    forces at once."""
    return np.array(pyramid_rows(np.eye(3), friction, shape))
