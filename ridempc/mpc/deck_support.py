"""The steering roll a rider's support on the deck holds while she pushes again.

A skateboard steers by its deck's roll (eq. 14), which the rider holds with her feet; rolled,
the deck moves her balance towards its lowered edge (the four-leg
:meth:`~ridempc.mpc.controller.LinearMpc.static_shift`). A push from the rolling deck
(``repush``) lifts one foot for about three seconds, swinging it to the ground, pushing,
swinging and pushing again; the three feet left on the deck hold a smaller support, over
which the entry keeps the centre of mass on a *level* deck. Rolled towards the lifted foot's
edge for a sustained turn, the balance moves out of that support, onto the missing foot; with
a foot on the ground, a turning deck turns under a foot that stands still.

So the steering roll at a node of the horizon is bounded by the support the reference has
there (:func:`steering_bounds`): the stance's whole map with every foot on the deck, none
with a foot on the ground (the deck comes level by the touchdown), and with a foot swinging
only the roll that lowers the other edge, up to :data:`SWING_ROLL`. What the rider cannot
steer meanwhile, the path follower takes back once the support is whole again.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["SWING_ROLL", "steering_bounds"]

Array = NDArray[np.float64]
# [rad] the largest steering roll held on three feet: half the four-leg stance's 0.12 rad
# (a full 0.12 rad in a swing moved the rider onto the lowered edge, docs/tuning.md)
SWING_ROLL: float = 0.06


def steering_bounds(
    reference: MotionReference, times: ArrayLike, sides: Array, swing_roll: float = SWING_ROLL
) -> tuple[Array, Array]:
    """The steering roll the support holds at reference ``times`` [s] (held at the first
    phase before the reference's start, at its last after its end): unbounded here with
    every foot on the deck, none with a foot on the ground, and with a foot swinging only
    towards the edge that lifts it (``sides`` [-], per contact, +1 left of the deck's
    centre line and -1 right; a positive roll lowers the right edge), up to ``swing_roll``
    [rad], so that the balance moves onto the feet left on the deck.

    Returns:
        The least and the largest roll at each time [rad].
    """
    times = np.asarray(times, dtype=float)
    interval = np.clip(
        np.floor((times - reference.times[0]) / reference.dt + 1e-9).astype(int),
        0,
        len(reference.schedule) - 1,
    )
    low = np.full(len(times), -np.inf)
    high = np.full(len(times), np.inf)
    for k, j in enumerate(interval):
        for contact, side in zip(reference.schedule[j], sides, strict=True):
            if contact is Contact.GROUND:
                low[k] = high[k] = 0.0
            elif contact is Contact.SWING:
                low[k] = max(low[k], 0.0 if side > 0 else -swing_roll)
                high[k] = min(high[k], swing_roll if side > 0 else 0.0)
    return low, high
