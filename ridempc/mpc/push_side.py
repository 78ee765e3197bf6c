"""Which foot pushes a re-push: the library's pusher or its mirror (:mod:`.mirrored`).

A push made from one side of a deck rolls the deck and turns the board away from that side
(on the simulated skateboard, a quadruped's rear left foot rolled the deck about +0.1 rad
and turned the board about 0.1 rad to the right, with no steering commanded), and while
that foot swings to and from the ground the rider balances on the three feet left on the
deck, whose support lies on the other side: she can lean, and so steer, into a turn away
from the lifted foot but not towards it. So each re-push is made with the foot on the side
*away from* the commanded turn's centre (:meth:`PushSide.side`): a left turn by the right
foot, a right turn by the left. Going straight (a yaw rate below :data:`TURN_BAND`), the
two sides alternate, each push's turn cancelling the last one's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from ridempc.boards.canonical import BoardState
from ridempc.mpc.mirrored import mirrored
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.mirror import Mirror, Symmetry
from ridempc.trajopt.schedule import Contact

__all__ = ["TURN_BAND", "PushSide", "first_stride", "pusher_side"]

# [rad/s] a commanded yaw rate below this goes straight: half the turn a push makes by itself
# (about 0.1 rad over its 1 s on the ground), so that a push on the wrong side would turn it
# no further off than alternating does
TURN_BAND: float = 0.05


def pusher_side(reference: MotionReference, symmetry: Symmetry) -> float | None:
    """The side of the foot that pushes in ``reference`` (+1 left, -1 right), or None
    where no foot is on the ground."""
    for step in reference.schedule:
        for contact, place in zip(reference.contact_names, step, strict=True):
            if place is Contact.GROUND and contact in symmetry.feet:
                return symmetry.side[symmetry.feet.index(contact)]
    return None


def first_stride(reference: MotionReference) -> tuple[float, float]:
    """From when a foot first leaves the deck to the end of the first push [s]: the time
    the rider balances on the other feet and leans whichever way the deck is steered."""
    start = end = elapsed = 0.0
    lifted = False
    for phase in reference.phases:
        if not lifted and any(c is not Contact.BOARD for c in phase.contacts):
            start, lifted = elapsed, True
        elapsed += phase.duration
        if Contact.GROUND in phase.contacts:
            end = elapsed
            break
    return start, max(end, start)


class PushSide:
    """Picks each re-push's side and mirrors the library's entry to push from it.

    Args:
        symmetry: The robot's left-right symmetry.
    """

    def __init__(self, symmetry: Symmetry) -> None:
        self.symmetry = symmetry
        self.last: float | None = None  # the side of the last re-push
        self._mirrors: dict[tuple[str, ...], Mirror] = {}

    def side(self, yaw_rate: float) -> float | None:
        """The side (+1 left, -1 right) to push from under a commanded ``yaw_rate``
        [rad/s] (left positive): away from a turn's centre, else the other side than the
        last push (None: the first push of a straight ride, either side)."""
        if abs(yaw_rate) >= TURN_BAND:
            return -math.copysign(1.0, yaw_rate)
        return None if self.last is None else -self.last

    def reference(
        self, reference: MotionReference, yaw_rate: float, board_states: Mapping[str, BoardState]
    ) -> MotionReference:
        """``reference`` (a re-push entry) as is or mirrored, to push from :meth:`side`.

        Args:
            reference: The library's entry, as retargeted.
            yaw_rate: The commanded yaw rate over the push ahead [rad/s].
            board_states: The pair's board states by name (canonical quantities).
        """
        own = pusher_side(reference, self.symmetry)
        if own is None:
            return reference
        wanted = self.side(yaw_rate)
        wanted = own if wanted is None else wanted
        self.last = wanted
        if wanted == own:
            return reference
        key = reference.state_names + reference.input_names
        if key not in self._mirrors:
            self._mirrors[key] = Mirror.of(
                self.symmetry, reference.state_names, reference.input_names, board_states
            )
        return mirrored(reference, self._mirrors[key])
