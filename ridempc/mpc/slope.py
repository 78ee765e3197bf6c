r"""The ground's slope under each platform, from the rider's own sensors (never a height map).

Each platform's velocity (the stance feet's, from the IMU and the leg kinematics,
:class:`~ridempc.estimation.state.BoardEstimate`) runs along the ground it rolls on, so the
slope along the platform's heading is

.. math:: \hat\alpha = \operatorname{atan2}(v_z,\ v_x \cos\psi + v_y \sin\psi),

positive when the ground rises ahead, low-passed over ``TIME_CONSTANT``. It is read only
while the platform rolls faster than ``MIN_SPEED`` (standing still, the direction of a
millimetre-per-second velocity is noise), and a sample steeper than ``MAX_SLOPE`` (a step's
drop, not a slope) leaves the estimate where it was.

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
from collections.abc import Sequence

from ridempc.estimation.state import BoardEstimate
from ridempc.gravity import GRAVITY

__all__ = ["GRAVITY", "MAX_SLOPE", "MIN_SPEED", "TIME_CONSTANT", "SlopeEstimator"]

# Below 0.15 m/s a centimetre-per-second error in the velocity tilts the estimate by 4 deg.
MIN_SPEED: float = 0.15  # [m/s]
# Steeper than any ramp a board is ridden on (the scenarios' steepest: 13 deg); a step's
# drop passes through 30-80 deg for a tenth of a second.
MAX_SLOPE: float = math.radians(25.0)  # [rad]
# Long enough to average the shoes' 4 Hz pitch oscillation, short against the ~6 s a ride
# spends on a 3 m incline.
TIME_CONSTANT: float = 0.3  # [s]


class SlopeEstimator:
    """Per platform, the ground's slope along its heading (the module docstring)."""

    def __init__(self, platforms: int, time_constant: float = TIME_CONSTANT) -> None:
        self.angles = [0.0] * platforms  # [rad] positive uphill
        self.time_constant = time_constant
        self._time: float | None = None

    def update(self, time: float, boards: Sequence[BoardEstimate]) -> list[float]:
        """Fold in one tick's platform estimates at ``time`` [s]; returns :attr:`angles`."""
        dt = 0.0 if self._time is None else max(0.0, time - self._time)
        self._time = time
        blend = 1.0 - math.exp(-dt / self.time_constant)
        for k, board in enumerate(boards[: len(self.angles)]):
            vx, vy, vz = board.velocity.tolist()
            along = vx * math.cos(board.yaw) + vy * math.sin(board.yaw)
            if math.hypot(along, vz) < MIN_SPEED:
                continue
            angle = math.atan2(vz, along) if along >= 0.0 else math.atan2(-vz, -along)
            if abs(angle) <= MAX_SLOPE:
                self.angles[k] += blend * (angle - self.angles[k])
        return self.angles

    @staticmethod
    def gravity_drag(angle: float, shoe_mass: float, load: float) -> float:
        r""":math:`G = -(m_s g + N)\sin\alpha` [N] along the heading (``load`` :math:`N` [N])."""
        return -(shoe_mass * GRAVITY + max(load, 0.0)) * math.sin(angle)
