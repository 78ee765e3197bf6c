"""The deck roll a four-foot stance can hold, from where the feet stand on the deck.

The dog rolls its skateboard's deck by shifting its centre of mass sideways: the trucks'
stiffness :math:`K_B \\varphi` must be held by the load's moment about the deck's centre.
Per metre of the estimated centre-of-mass offset from the feet's centroid
(:math:`\\hat c_y - \\hat o_y`) the deck rolls 2.37 rad in closed loop
(:mod:`~ridempc.mpc.roll_observer`): a roll :math:`\\varphi` asks for
:math:`y(\\varphi) = y_0 - s\\varphi` with :math:`s` = 0.42 m/rad, :math:`y_0` the offset
that holds the deck level (0.40-0.44 m/rad measured at the roll wave's 0.1 rad).

The offset must stay inside the stance: while the far-side feet still carry the MPC's
least force on a deck :math:`f_{min}` each, the load's moment about the near side's line
(the two feet on it, at the centre of mass's place along the deck) is at least
:math:`2 f_{min} w`, :math:`w` the stance's width there, so with the weight :math:`W`

.. math::

    y_R + \\frac{2 f_{min} w}{W} + m \\le y(\\varphi) \\le y_L - \\frac{2 f_{min} w}{W} - m

with :math:`y_R, y_L` the right and left lines' lateral places (deck frame, from the feet's
centroid) and :math:`m` a margin [m]. The bounds on :math:`\\varphi` follow from the
estimated :math:`y_0 = \\hat y + s\\hat\\varphi` (the offset and roll now), low-passed over
``time_constant`` (the sway swings it +-1 cm at the roll wave's 3 s period). On a normal
stance the bound lies beyond the roll wave's 0.1 rad; it binds where a foot has landed
inward, narrowing the stance (``docs/tuning.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["StanceLimit", "support_lines"]

Array = NDArray[np.float64]


def support_lines(feet: Array, at: float) -> tuple[float, float]:
    """The right and left support lines' lateral places [m] at ``at`` along the deck.

    Args:
        feet: Four feet's (along, across) places in the deck frame [m], shape (4, 2).
        at: The place along the deck where the lines are read [m].

    Returns:
        :math:`(y_R, y_L)`: the line through the two rightmost feet, and through the two
        leftmost, at ``at`` (the pair's mean lateral place if they stand side by side).
    """
    points = np.asarray(feet, dtype=float).reshape(4, 2)
    order = np.argsort(points[:, 1])
    out = []
    for pair in (points[order[:2]], points[order[2:]]):
        (x0, y0), (x1, y1) = pair
        if abs(x1 - x0) < 1e-6:
            out.append(0.5 * (y0 + y1))
        else:
            out.append(y0 + (y1 - y0) * (at - x0) / (x1 - x0))
    return out[0], out[1]


@dataclass
class StanceLimit:
    """The deck roll the stance can hold (module docstring).

    Attributes:
        offset_per_roll: :math:`s` [m/rad], the estimated centre-of-mass offset a radian of
            deck roll asks for.
        margin: :math:`m` [m].
        time_constant: Of the low-pass on :math:`y_0` [s].
        level: :math:`y_0` [m], or None before the first update.
        last: The last bounds [rad], held while a foot is off the deck (its place is not
            the stance's then).
    """

    offset_per_roll: float
    margin: float = 0.0
    time_constant: float = 0.5
    level: float | None = None
    last: tuple[float, float] = (-math.inf, math.inf)

    def reset(self) -> None:
        """Forget :math:`y_0` and the bounds (the stance changes: a push-off)."""
        self.level, self.last = None, (-math.inf, math.inf)

    def bounds(
        self, feet: Array, com: Array, roll: float, dt: float, far_share: float
    ) -> tuple[float, float]:
        """Update :math:`y_0` and give the deck roll's bounds.

        Args:
            feet: The four feet's (along, across) places in the deck frame, from their
                centroid [m], shape (4, 2).
            com: The centre of mass's (along, across) place, likewise [m].
            roll: The estimated deck roll :math:`\\hat\\varphi` [rad].
            dt: Time since the last update [s].
            far_share: :math:`2 f_{min} / W` [-], the far-side feet's least share of the
                weight.

        Returns:
            The least and the greatest deck roll [rad] (low <= high; both the roll that
            centres the offset between the lines when they are too close).
        """
        level = float(com[1]) + self.offset_per_roll * roll
        if self.level is None:
            self.level = level
        else:
            self.level += min(1.0, dt / self.time_constant) * (level - self.level)
        right, left = support_lines(feet, float(com[0]))
        keep = far_share * (left - right) + self.margin
        low, high = right + keep, left - keep
        if low > high:
            low = high = 0.5 * (low + high)
        # y(phi) = y0 - s phi in [low, high]
        s = self.offset_per_roll
        self.last = ((self.level - high) / s, (self.level - low) / s)
        return self.last
