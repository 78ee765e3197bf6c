"""A re-push's steering roll: the turn its straight strokes lose made up in its swings, within
the roll the stance holds, laid in at the rate the stance follows.

A re-push's strokes go straight (:mod:`~ridempc.mpc.push_steer`): the deck's steering roll
is let go over each stroke and the weight shift around it, so over an entry the board turns
only for the share :math:`\\bar s` of its time that steers, and a commanded yaw rate
:math:`\\omega^*` is met only :math:`\\bar s` of the way. The turn lost (0.07 rad a stroke
at 0.2 rad/s) is made up in the swings: the steering roll of a steering node is asked
:math:`1/\\bar s` times the commanded turn's, so the entry's mean turn is the commanded one.

That roll is held within :data:`~ridempc.boards.skateboard.steering.STANCE_ROLL` (the
paper's largest, 0.12 rad; beyond it the far feet unload) and laid in at no more than
:data:`ROLL_RATE`: a steering roll laid on at once (at a stroke's lift-off, or where a path's
turn begins as a re-push does) moved the reference's balance across the deck in one step
and handed the rider over.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.skateboard.steering import STANCE_ROLL
from ridempc.mpc.push_steer import SETTLE, steering_nodes
from ridempc.mpc.reference import MotionReference

__all__ = ["ROLL_RATE", "RollRate", "repush_steering", "steering_share", "turn_makeup"]

Array = NDArray[np.float64]

# [rad/s] the stance's whole roll laid in over the settle after a stroke (the body back over
# the deck's centre line within 0.2 s of the foot's lift-off, :data:`SETTLE`): 0.6 rad/s
ROLL_RATE: float = STANCE_ROLL / SETTLE
# [s] the share is read on this grid: a twentieth of the shortest ramp (the settle, 0.2 s)
SHARE_STEP: float = 0.01


def steering_share(reference: MotionReference) -> float:
    """:math:`\\bar s` [-]: the mean of :func:`~ridempc.mpc.push_steer.steering_nodes` over
    ``reference``'s whole length (1 for an entry with no foot on the ground)."""
    length = float(sum(phase.duration for phase in reference.phases))
    count = max(2, round(length / SHARE_STEP) + 1)
    return float(np.mean(steering_nodes(reference, 0.0, count, SHARE_STEP)))


def turn_makeup(share: Array, mean_share: float) -> Array:
    """Each node's multiple [-] of the commanded turn's steering roll: its ``share`` of
    steering (:func:`~ridempc.mpc.push_steer.steering_nodes`) over the entry's
    ``mean_share`` :math:`\\bar s`, so that the entry's mean turn is the commanded one."""
    share = np.asarray(share, dtype=float)
    return share / mean_share if mean_share > 0.0 else np.zeros_like(share)


def repush_steering(reference: MotionReference, t_ref: float, nodes: int, dt: float) -> Array:
    """Per node of the horizon from the reference's time ``t_ref`` [s] (``nodes`` nodes
    ``dt`` [s] apart), the multiple [-] of the commanded turn's steering roll it is given: 0
    over ``reference``'s strokes, the turn they lose made up in its swings."""
    share = steering_nodes(reference, t_ref, nodes, dt)
    return turn_makeup(share, steering_share(reference))


class RollRate:
    """The commanded deck roll over the horizon, held within :math:`\\pm` ``limit`` [rad] and
    changing by at most ``rate`` [rad/s], from node to node and from the last tick's first
    node on; :meth:`follow` takes a tick's roll as it is (where the stance limits it
    otherwise), so a re-push starts from the roll the rider holds.

    Args:
        rate: Largest rate of the commanded roll [rad/s].
        limit: Largest commanded roll [rad].
    """

    def __init__(self, rate: float = ROLL_RATE, limit: float = STANCE_ROLL) -> None:
        self.rate, self.limit = rate, limit
        self._last: tuple[float, float] | None = None  # (time [s], first node's roll [rad])

    def follow(self, roll: Array, now: float) -> Array:
        """``roll`` [rad] unchanged, its first node remembered at ``now`` [s]."""
        self._last = (now, float(roll[0]))
        return roll

    def __call__(self, roll: Array, now: float, dt: float) -> Array:
        """``roll`` [rad] at nodes ``dt`` [s] apart from ``now`` [s], clipped and rate-limited."""
        out = np.clip(np.asarray(roll, dtype=float), -self.limit, self.limit)
        previous = None
        if self._last is not None and now >= self._last[0]:
            previous = self._last[1]
            span = self.rate * (now - self._last[0])
        for k in range(len(out)):
            if previous is not None:
                out[k] = np.clip(out[k], previous - span, previous + span)
            previous, span = float(out[k]), self.rate * dt
        self._last = (now, float(out[0]))
        return out
