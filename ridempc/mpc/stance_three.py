"""The deck roll a three-foot stance can hold: a re-push's swing, one foot off the deck.

With three feet on the deck their loads are statically determinate: the weight :math:`W`
[N] over the centre of mass's ground point :math:`c` splits as

.. math::

    f_i = W \\lambda_i(c), \\qquad \\sum_i \\lambda_i = 1, \\qquad \\sum_i \\lambda_i p_i = c,

:math:`\\lambda_i` the barycentric coordinates of :math:`c` in the feet's triangle
:math:`p_0 p_1 p_2` (deck frame, along and across [m]). Each foot keeps the MPC's least
force on a deck :math:`f_{min}` [N] and stays a margin :math:`m` [m] inside the triangle
while

.. math::

    \\lambda_i(c) \\ge \\frac{f_{min}}{W} + m \\lVert \\nabla \\lambda_i \\rVert,

:math:`1 / \\lVert \\nabla \\lambda_i \\rVert` foot :math:`i`'s height over the opposite
edge. At the centre of mass's place along the deck each :math:`\\lambda_i` is affine in the
lateral offset :math:`y`, so the three rows give an interval :math:`[y_{lo}, y_{hi}]`. The
deck's trucks turn it into a roll interval as the four-foot stance's does
(:mod:`~ridempc.mpc.stance`): :math:`y(\\varphi) = y_0 - s \\varphi`.

Against the four-foot stance's two lines, :math:`\\pm w/2` less :math:`2 f_{min} w / W`,
the triangle's edges are one side's line (the two feet left on it) and the diagonal from
its far foot to the lone foot on the other side, which runs through the deck's middle: on
the CyberDog2's stance (0.33-0.38 m by 0.17 m, :math:`f_{min} = 0.1 W`) with the right rear
foot off the deck and the deck level over the four feet's centroid,
:math:`\\varphi \\in [-0.17, -0.04]` rad (four feet: :math:`\\pm 0.12`): the deck must
roll towards the side that keeps both feet, and may roll about 1.4 times as far that way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["ThreeFootLimit", "triangle_span"]

Array = NDArray[np.float64]


def triangle_span(feet: Array, at: float, least_share: float, margin: float) -> tuple[float, float]:
    """The lateral places [m] of the centre of mass, at ``at`` [m] along the deck, that keep
    each of three feet loaded (module docstring).

    Args:
        feet: The three feet's (along, across) places in the deck frame [m], shape (3, 2).
        at: The centre of mass's place along the deck [m].
        least_share: :math:`f_{min} / W` [-], a foot's least share of the weight.
        margin: :math:`m` [m].

    Returns:
        :math:`(y_{lo}, y_{hi})`, both the middle of the crossing when no offset keeps all
        three loaded; (0, 0) for feet in a line.
    """
    points = np.asarray(feet, dtype=float).reshape(3, 2)
    corners = np.vstack([points.T, np.ones(3)])  # [p_0 p_1 p_2; 1 1 1] lambda = [c; 1]
    if abs(np.linalg.det(corners)) < 1e-9:
        return 0.0, 0.0
    inverse = np.linalg.inv(corners)  # row i: lambda_i = a x + b y + d
    low, high = -np.inf, np.inf
    for a, b, d in inverse:
        need = least_share + margin * float(np.hypot(a, b)) - (a * at + d)  # b y >= need
        if abs(b) < 1e-12:
            if need > 0.0:  # no offset keeps this foot loaded at this place
                low, high = np.inf, -np.inf
            continue
        if b > 0.0:
            low = max(low, need / b)
        else:
            high = min(high, need / b)
    if low > high:
        if np.isfinite(low) and np.isfinite(high):
            low = high = 0.5 * (low + high)
        else:
            return 0.0, 0.0
    return float(low), float(high)


@dataclass
class ThreeFootLimit:
    """The deck roll three feet on the deck can hold (module docstring).

    Attributes:
        offset_per_roll: :math:`s` [m/rad] (the four-foot stance's: the trucks' own).
        margin: :math:`m` [m].
        time_constant: Of the low-pass on :math:`y_0` [s].
        level: :math:`y_0` [m] from the three feet's centroid, or None before the first
            update of a swing.
    """

    offset_per_roll: float
    margin: float = 0.0
    time_constant: float = 0.5
    level: float | None = None

    def reset(self) -> None:
        """Forget :math:`y_0` (the swing is over)."""
        self.level = None

    def bounds(
        self, feet: Array, com: Array, roll: float, dt: float, least_share: float
    ) -> tuple[float, float]:
        """Update :math:`y_0` and give the deck roll's bounds.

        Args:
            feet: The three feet's (along, across) places in the deck frame, from their
                centroid [m], shape (3, 2).
            com: The centre of mass's (along, across) place, likewise [m].
            roll: The estimated deck roll :math:`\\hat\\varphi` [rad].
            dt: Time since the last update [s].
            least_share: :math:`f_{min} / W` [-].

        Returns:
            The least and the greatest deck roll [rad] (low <= high).
        """
        s = self.offset_per_roll
        level = float(com[1]) + s * roll
        if self.level is None:
            self.level = level
        else:
            self.level += min(1.0, dt / self.time_constant) * (level - self.level)
        low, high = triangle_span(feet, float(com[0]), least_share, self.margin)
        return (self.level - high) / s, (self.level - low) / s
