"""A re-push's steering roll eased out before each foot reaches the ground.

While a re-push's foot swings, the rider steers by the deck's roll like a coasting one (the
three feet on the deck lean her, with the deck, into the turn); while that foot is on the
ground the deck goes straight. Switched off only at the touchdown, the deck still lay rolled
into the turn as the foot pushed (-0.04 to -0.08 rad in a held left circle, the reference
asking for 0), the rider's weight on the deck's inner feet: the MPC loaded the pushing foot
with 0-18 N instead of the entry's 32-36 N, its friction pyramid let it push forwards with
0-8 N instead of 15 N, and a push in the turn regained 0.03 m/s where a straight one
regained 0.16 (seed 0, the first push). So the steering roll is eased out over the last
:data:`EASE` of each swing towards the ground, node by node over the MPC's horizon: the deck
is level, and the weight back over the pushing side, when the foot lands (the same push then
regained 0.10 m/s); after the last push it steers again. Only the roll that *raises* the
pushing foot's edge is eased (:func:`eased_roll`): one that lowers it, as when a turn has
changed sides since the push's foot was chosen (``yaw-steps-hold``), already leans the rider
onto that foot, and easing it too left a swing unsteered before an alternating turn.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["EASE", "eased_roll", "touchdown_ease"]

Array = NDArray[np.float64]

# [s] how long before a touchdown the steering roll is eased out: two of the MPC's 1/30 s
# steps beyond the deck's own lag behind the plan (the pair's ``roll_lead``, 0.08 s),
# the least that has the deck level as the foot lands; longer, the swing before an
# alternating turn's push went unsteered (0.3 s: yaw-steps-hold seed 0 fell at the push)
EASE: float = 0.15


def touchdown_ease(reference: MotionReference, times: Array, ease: float = EASE) -> Array:
    """The share of the steering roll kept at ``times`` [s] since the reference's start:
    0 with a foot on the ground, rising linearly from 0 at a touchdown to 1 ``ease`` [s]
    before it, 1 where no touchdown lies ahead (after the last push, or before the entry's
    start)."""
    times = np.asarray(times, dtype=np.float64)
    ground = np.array(
        [any(c is Contact.GROUND for c in step) for step in reference.schedule], dtype=bool
    )
    if not ground.any():
        return np.ones_like(times)
    starts = reference.times[0] + reference.dt * np.arange(len(ground))
    ground_starts = starts[ground]
    index = np.floor((times - reference.times[0]) / reference.dt + 1e-9).astype(int)
    inside = (index >= 0) & (index < len(ground))
    on_ground = np.zeros(len(times), dtype=bool)
    on_ground[inside] = ground[index[inside]]
    # the next ground interval's start at or after each time
    following = np.searchsorted(ground_starts, times - 1e-9)
    ahead = np.full(len(times), np.inf)
    has_next = following < len(ground_starts)
    ahead[has_next] = ground_starts[following[has_next]] - times[has_next]
    share = np.clip(ahead / max(ease, 1e-9), 0.0, 1.0)
    share[on_ground] = 0.0
    return share


def eased_roll(steering: Array, share: Array, side: float | None) -> Array:
    """The steering roll ``steering`` [rad] at the horizon's nodes with the part that raises
    the pushing foot's edge scaled by ``share`` (:func:`touchdown_ease`).

    Args:
        steering: The steering roll at each node [rad] (positive: the right edge down).
        share: The share kept at each node [-].
        side: The pushing foot's side (+1 left, -1 right), or None where it is not known
            (every roll eased).
    """
    steering = np.asarray(steering, dtype=np.float64)
    if side is None:
        return share * steering
    raises = steering * side > 0.0  # a left foot's edge rises with the right edge down
    return np.where(raises, share * steering, steering)
