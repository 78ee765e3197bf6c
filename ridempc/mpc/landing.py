"""A drop's landing ridden flat-footed: each foot's load centred on its platform for a moment.

Through a drop's flight (:mod:`~ridempc.mpc.flight`) the shoes' wheels spin free, so the
speeds the plans read off their encoders are the wheels', not the shoes', and the wheels
land at another speed than their shoes: the ground's friction on the touchdown pitches
each shoe and its firmware surges or brakes it. The reduced model (eq. (8): a shoe
accelerates with its pitch, :math:`m\\dot v = c_4\\theta`) then plans each foot's centre of
pressure to pitch its shoe back to the reference's speed, and on top of the firmware's own
response the heels' load stops the shoes within 0.1 s, pitched nose up past what the decks
clear over the step's edge. For ``window`` [s] after the landing, each foot's planned load
is instead shared evenly between its contact sites,

.. math:: f_s = \\frac{1}{n_i} \\sum_{s' \\in i} f_{s'} \\quad (s \\in \\text{foot } i),

the foot's total force (what holds the rider up) kept and no pitching moment put on its
platform about the foot's centre, which stands over the shoe's axle (the identified
offset is 2 mm): the firmware levels the shoes alone and they roll on, as a rider lands
flat-footed. Afterwards the plan's centre of pressure is applied again.

Only a deep landing is ridden so: one whose fall, as the rider measured it
(:attr:`~ridempc.mpc.flight.DropFlight.depth`), reaches ``depth`` [m], the fall from which
a shoe braked nose up just past the edge can put its deck's rear on the step,

.. math:: h \\ge h_{deck} - l_{rear} \\sin\\theta_{brake},

(:math:`h_{deck}` [m] the deck's underside above the ground, :math:`l_{rear}` [m] its
overhang behind the axle, :math:`\\theta_{brake}` [rad] the pitch the heels' load can give a
braked shoe). On a shallower landing the deck clears the edge at any pitch a shoe rides, and
the plan's centre of pressure, which brakes the landed shoes back under the rider, rides it.
The window also ends at the next take-off: a landing's loads never reach into another flight.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.flight import DropFlight

__all__ = ["LANDING_S", "LandingLoads"]

Array = NDArray[np.float64]

# [s] twice the landing's surge: the shoes kicked at the touchdown are back under the
# rider's speed by their firmware within 0.08-0.1 s (`step-down-171`), and the plans
# solved in the air (3 MPC steps) are then replaced by plans from the ground.
LANDING_S: float = 0.2


class LandingLoads:
    """Each foot's load centred on its platform for ``window`` after a flight's landing.

    Args:
        flight: The drop's flight stage (its ``landed`` time and ``depth``).
        contact_foot: Per contact site, its foot.
        window: How long after the landing the loads stay centred [s].
        depth: The shallowest fall whose landing is ridden so [m] (0: every landing).
    """

    def __init__(
        self,
        flight: DropFlight,
        contact_foot: Sequence[int],
        window: float = LANDING_S,
        depth: float = 0.0,
    ) -> None:
        if not window > 0.0 or not depth >= 0.0:
            raise ValueError(f"landing: window {window} must be > 0 and depth {depth} >= 0")
        self.flight = flight
        self.window = window
        self.depth = depth
        feet = max(contact_foot) + 1 if len(contact_foot) else 0
        to_feet = np.zeros((feet, len(contact_foot)))
        to_feet[list(contact_foot), np.arange(len(contact_foot))] = 1.0
        counts = np.maximum(to_feet.sum(axis=1, keepdims=True), 1.0)
        # site <- the mean of its foot's sites: (sites x sites)
        self._share: Array = (to_feet / counts).T.dot(to_feet)

    def landing(self, now: float) -> bool:
        """Whether ``now`` [s] is within ``window`` after the last flight's landing, that
        flight fell at least ``depth`` and no other has taken off since."""
        flight = self.flight
        landed, depth = flight.landed, flight.depth
        if landed is None or depth is None or depth < self.depth or flight.flying:
            return False
        return 0.0 <= now - landed < self.window

    def __call__(self, site_forces: Array, now: float) -> Array:
        """The site forces [N] (sites x 3) to apply at ``now`` [s]: each foot's mean on each
        of its sites while landing, else ``site_forces`` as they are."""
        if not self.landing(now):
            return site_forces
        return self._share.dot(site_forces)
