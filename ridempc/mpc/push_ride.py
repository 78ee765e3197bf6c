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

So a push read inside the band while the state is still within the handover's bound
starts a ride-out: the deviation's handover waits until the push has left the observer's
window and the state is back within the bound (the excursion the push made is over; a
deviation beyond the bound after that is the MPC's own, and hands over as before). The
recovery may take longer than the push's 0.4 s in the window
(:data:`~ridempc.mpc.impulse.WINDOW_S`): on the Go1 (`hard` seed 181 v0025, a 2.9 N/kg
push for 0.14 s) the deviation stayed at 3.7-4.0 for a second after the push and came
back within 3.0 1.2 s after it; handed over at the window's end the PD fell, ridden out the
MPC stood. A failed plan, a whole-body QP on slack or a push beyond the band still hand
over at once. A pair opts in with ``[stages.impulse] ride_floor``: the share of the band's
ellipse (:math:`r` below) from which a reading counts as a push rather than the observer's
residual between pushes (its noise and the rider's own unmodelled forces).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

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
    """The deviation's handover deferred over a push's excursion (see the module
    docstring).

    Args:
        floor: The pair's ``ride_floor`` [-].
        bound: The pair's handover deviation [-] (``[mpc] handover_deviation``).
    """

    def __init__(self, floor: float, bound: float) -> None:
        self.floor, self.bound = floor, bound
        self.active = False

    def reset(self) -> None:
        """Nothing ridden out (the backup rides)."""
        self.active = False

    def update(self, share: float, deviation: float) -> bool:
        """Whether the deviation's handover waits this tick, with the push read at
        ``share`` of the band and the state at ``deviation`` [-] of its reference: from a
        push inside the band found with the state within the bound, while the push is read
        or the state is beyond the bound."""
        if self.active:
            self.active = share <= 1.0 and (share >= self.floor or deviation > self.bound)
        else:
            self.active = rides_push(share, self.floor) and deviation <= self.bound
        return self.active
