"""A push inside the impulse band is ridden out: its deviation does not hand the ride over.

The pair's impulse band (:mod:`~ridempc.mpc.impulse`) is the velocity change the MPC's
model rides: along a board's travel, the capture point's reach to the feet,
:math:`x_f \\sqrt{g/h}`; across it, the rider tipping over the wheels' line,
:math:`w/2 \\sqrt{g/H}` [m/s]. A push beyond it is handed to the backup at once. A push
within it throws the state off its reference by the push itself: the centre of mass
moves at :math:`\\Delta v` for a divergence time before the plan's forces take it back, so
the state's deviation (:func:`~ridempc.mpc.handover.deviation`) passes the handover's
bound in the push's first 0.1-0.25 s although the plan is already taking it back. Handing
over then contradicts the band: the backup inherits a rider mid-recovery, with the
contact forces at the plan's and the trunk moving, rather than a push it could ride from
the start.

So from the tick the impulse observer reads a push inside the band, the deviation's
handover waits until the rider has settled again (its deviation back within
:data:`~ridempc.mpc.handover.RETURN_DEVIATION`, the band in which the MPC may take a ride
back): the recovery takes longer than the push's 0.4 s in the observer's window
(:data:`~ridempc.mpc.impulse.WINDOW_S`; deferred only while the push was in it, Go1 `hard`
seed 181 v0025 was handed over 0.48 s after its push, at 3.9, and the handed PD fell,
where the MPC alone rides it). A failed plan, a whole-body QP on slack or a push beyond
the band still hand over at once. A pair opts in with ``[stages.impulse] ride_floor``:
the share of the band's ellipse (:math:`r` below) from which a reading counts as a push
rather than the observer's idle residual (its noise and the rider's own unmodelled
forces).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.handover import RETURN_DEVIATION

__all__ = ["RideOut", "band_share", "rides_push"]


def band_share(impulse: NDArray[np.float64], heading: float, band: float, sideways: float) -> float:
    """The push's share of the band's ellipse [-],
    :math:`r = \\sqrt{(\\Delta v_{along}/b)^2 + (\\Delta v_{across}/b_s)^2}`, for the
    horizontal ``impulse`` [m/s] (world frame) of a rider heading ``heading`` [rad], with
    half-axes ``band`` along and ``sideways`` across [m/s]."""
    c, s = math.cos(heading), math.sin(heading)
    along = c * float(impulse[0]) + s * float(impulse[1])
    across = -s * float(impulse[0]) + c * float(impulse[1])
    return math.hypot(along / band, across / sideways)


def rides_push(share: float, floor: float | None) -> bool:
    """Whether the deviation's handover waits: a push read at ``share`` of the band
    (:func:`band_share`) from the pair's ``floor`` [-] up to the band itself; never
    without a floor (the pair not opted in)."""
    return floor is not None and floor <= share <= 1.0


class RideOut:
    """The deviation's handover deferred from a push read inside the band until the
    rider has settled (see the module docstring).

    Args:
        floor: The pair's ``ride_floor`` [-].
    """

    def __init__(self, floor: float) -> None:
        self.floor = floor
        self.active = False

    def reset(self) -> None:
        """Nothing ridden out (the backup rides)."""
        self.active = False

    def update(self, share: float, deviation: float) -> bool:
        """Whether the deviation's handover waits this tick, with the push read at
        ``share`` of the band and the state at ``deviation`` [-] of its reference."""
        if rides_push(share, self.floor):
            self.active = True
        elif share > 1.0 or deviation <= RETURN_DEVIATION:
            self.active = False
        return self.active
