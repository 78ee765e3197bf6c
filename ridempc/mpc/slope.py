r"""The ground's slope under each platform, from the rider's own sensors (never a height map).

Each platform's position (the stance feet's contact centroid, from the IMU, the leg kinematics
and the VIO, :class:`~ridempc.estimation.state.BoardEstimate`) rides on the ground it rolls
on, so the slope along the platform's heading is the height it lost over the distance it
rolled:

.. math:: \hat\alpha = \arctan\frac{\sum_i (s_i - \bar s)(z_i - \bar z)}{\sum_i (s_i - \bar s)^2},
          \qquad \Delta s = \Delta x \cos\psi + \Delta y \sin\psi,

positive when the ground rises ahead: the least-squares line through the platform's height
:math:`z_i` against the distance :math:`s_i` it rolled along its heading (backing up rolls it
back), sampled every ``WINDOW / SAMPLES`` over the last ``WINDOW`` [m] (the fit, not the
window's two ends: a millimetre of noise on the height is 0.5 deg over the ends of 15 cm, 0.2
deg over the fit's 50 samples). It needs no speed: a platform that slows
to a stop keeps the slope it stands on, and one that rolls on reads the new ground's slope
within ``WINDOW`` of travel, however slowly it rolls. A tick whose height changes faster than
``MAX_SLOPE`` allows and faster than ``DROP_SPEED`` (the platform's estimated velocity) is
a step's drop, not a slope: the window starts again after it and the estimate
holds until it has rolled ``WINDOW`` on.

On a slope the ground's reaction on a shoe's wheel leans back with it: along the shoe's
heading the shoe and the load on it lose

.. math:: G = -(m_s g + N)\sin\hat\alpha \quad [N],

(:math:`m_s` [kg] the shoe, :math:`N` [N] the rider's load on it) which the Hovershoes'
reduced model (eq. (8), written for level ground) leaves out; :mod:`ridempc.mpc.shoe_observer`
adds it to each shoe's drag at once, instead of fitting it over its memory (a 7 deg incline
is 24 N per shoe under Cassie: fitted over 1 s, the shoes first sagged to 0.3 m/s, then ran
to 1.2 m/s as the fit caught up).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from ridempc.estimation.state import BoardEstimate
from ridempc.gravity import GRAVITY

__all__ = ["DROP_SPEED", "GRAVITY", "MAX_SLOPE", "SAMPLES", "WINDOW", "SlopeEstimator"]

# Steeper than any ramp a board is ridden on (the scenarios' steepest: 13 deg); a step's
# drop passes through 30-80 deg for a tenth of a second.
MAX_SLOPE: float = math.radians(25.0)  # [rad]
WINDOW: float = 0.2  # [m]
# [m/s] a step's drop: a wheel falling 5 mm off an edge already sinks this fast, while a ride
# down 13 deg at 1 m/s (the shoes' fastest on it) sinks at 0.23 m/s
DROP_SPEED: float = 0.3


# [-] the samples a window holds, one per 1/SAMPLES of it rolled, however slowly: a
# platform standing still adds none
SAMPLES: int = 50


def _fitted_slope(track: deque[tuple[float, float]]) -> float:
    """The least-squares slope dz/ds [-] of the (s, z) samples (at least two, s apart)."""
    n = len(track)
    mean_s = sum(p[0] for p in track) / n
    mean_z = sum(p[1] for p in track) / n
    ss = sum((p[0] - mean_s) ** 2 for p in track)
    return sum((p[0] - mean_s) * (p[1] - mean_z) for p in track) / ss


class SlopeEstimator:
    """Per platform, the ground's slope along its heading (the module docstring)."""

    def __init__(self, platforms: int, window: float = WINDOW) -> None:
        self.angles = [0.0] * platforms  # [rad] positive uphill
        self.window = window
        # per platform: (distance rolled s [m], height z [m]) over the last window
        self._track: list[deque[tuple[float, float]]] = [deque() for _ in range(platforms)]
        self._last: list[tuple[float, float, float] | None] = [None] * platforms
        self._rolled = [0.0] * platforms  # [m] s now

    def update(self, time: float, boards: Sequence[BoardEstimate]) -> list[float]:
        """Fold in one tick's platform estimates at ``time`` [s]; returns :attr:`angles`."""
        steep = math.tan(MAX_SLOPE)
        for k, board in enumerate(boards[: len(self.angles)]):
            x, y, z = board.position.tolist()
            last, track = self._last[k], self._track[k]
            self._last[k] = (x, y, z)
            if last is None:
                track.append((0.0, z))
                continue
            cos, sin = math.cos(board.yaw), math.sin(board.yaw)
            s = self._rolled[k] = self._rolled[k] + (x - last[0]) * cos + (y - last[1]) * sin
            vx, vy, vz = board.velocity.tolist()
            along = vx * cos + vy * sin
            if abs(vz) > DROP_SPEED and abs(vz) > steep * abs(along):
                track.clear()  # a step's drop: the ground after it starts a new window
                track.append((s, z))
                continue
            if abs(s - track[-1][0]) < self.window / SAMPLES:
                continue  # not rolled far enough for a new sample
            track.append((s, z))
            while len(track) > 2 and abs(s - track[1][0]) >= self.window:
                track.popleft()
            if abs(s - track[0][0]) >= self.window:
                angle = math.atan(_fitted_slope(track))
                if abs(angle) <= MAX_SLOPE:
                    self.angles[k] = angle
        return self.angles

    @staticmethod
    def gravity_drag(angle: float, shoe_mass: float, load: float) -> float:
        r""":math:`G = -(m_s g + N)\sin\alpha` [N] along the heading (``load`` :math:`N` [N])."""
        return -(shoe_mass * GRAVITY + max(load, 0.0)) * math.sin(angle)
