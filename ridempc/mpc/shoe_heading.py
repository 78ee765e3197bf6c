"""Each Hovershoe's heading from its direction of travel: the rider's foot slips in yaw on it.

The estimator reads a Hovershoe's heading off the toe line of the foot standing on it
(:mod:`ridempc.estimation.board`), and assumes the sole holds on the pad. It does not quite:
a turning shoe's wheel scrubs, eq. (5)'s :math:`c_3\\dot\\psi` (18 N m s/rad: 7 N m at 0.4
rad/s), the sole turns it through friction alone, and it creeps round on the pad at a
quarter of its friction limit: in a long turn the toe lines run ahead of their shoes by
tenths of a radian, the MPC, seeing shoes turned further than they are, lets them lag the
rider, and the outer shoe runs wide. The creep is MuJoCo's soft friction, which the
scene's no-slip iterations do not quite take out (more of them would take out the tyres'
creep too, which eq. (5) needs), and a sole may slip on a real pad too. The heading the
feet cannot tell, their direction of travel can: a wheel rolls along its heading and does
not slide sideways, so at speed the foot moves along its shoe. Per shoe, the slip of the
toe line on the pad is low-passed from the difference:

.. math::

    \\chi = \\operatorname{atan2}(\\dot c_y, \\dot c_x) \\;(+\\pi \\text{ backwards}), \\qquad
    s \\leftarrow s + \\frac{\\Delta t}{T} \\operatorname{wrap}(\\psi_{toe} - \\chi - s),
    \\qquad \\psi = \\psi_{toe} - s,

with :math:`\\dot c` [m/s] the foot's estimated velocity, :math:`\\psi_{toe}` [rad] its toe
line's heading, :math:`T` = ``TIME_CONSTANT`` [s] and :math:`\\Delta t` [s] the tick; only
above ``MIN_SPEED``, below which the direction of travel is noise and :math:`s` is held.
The toe line keeps the heading's fast part, the travel its slow part. The foot's own
turn about the wheel's yaw axis adds :math:`\\dot\\psi\\, d` [m/s] sideways at a foot
:math:`d` ahead of it (under 0.03 rad at 0.8 m/s, 0.4 rad/s and 5 cm), left in. The creep
is then taken up by the hips' yaw.
"""

from __future__ import annotations

import math

import numpy as np

from ridempc.estimation.state import BoardEstimate, EstimatedState
from ridempc.frozen import changed
from ridempc.rotations import wrap_angle

__all__ = ["MIN_SPEED", "TIME_CONSTANT", "ShoeHeading"]

MIN_SPEED: float = 0.25  # [m/s] below this a shoe's slip estimate is held
TIME_CONSTANT: float = 1.0  # [s] the slip's low-pass


class ShoeHeading:
    """Each platform's toe-line slip :math:`s` [rad] (module docstring), and the estimate
    with the headings it corrects.

    Args:
        platforms: How many shoes.
        time_constant: :math:`T` [s].
        min_speed: Least speed at which the slip is updated [m/s].
    """

    def __init__(
        self,
        platforms: int,
        time_constant: float = TIME_CONSTANT,
        min_speed: float = MIN_SPEED,
    ) -> None:
        self.platforms = platforms
        self.time_constant, self.min_speed = time_constant, min_speed
        self.slip = np.zeros(platforms)
        self._time: float | None = None

    def __call__(self, estimate: EstimatedState) -> EstimatedState:
        """Fold in one tick and return the estimate with each shoe's heading
        :math:`\\psi_{toe} - s`."""
        if len(estimate.boards) != self.platforms:
            return estimate
        dt = 0.0 if self._time is None else max(estimate.time - self._time, 0.0)
        self._time = estimate.time
        share = min(dt / self.time_constant, 1.0)
        boards: list[BoardEstimate] = []
        for k, board in enumerate(estimate.boards):
            vx, vy = float(board.velocity[0]), float(board.velocity[1])
            if share > 0.0 and math.hypot(vx, vy) > self.min_speed:
                travel = math.atan2(vy, vx)
                if vx * math.cos(board.yaw) + vy * math.sin(board.yaw) < 0.0:
                    travel += math.pi  # rolling backwards
                self.slip[k] += share * wrap_angle(board.yaw - travel - self.slip[k])
            boards.append(changed(board, yaw=wrap_angle(board.yaw - float(self.slip[k]))))
        return changed(estimate, boards=tuple(boards))
