"""A re-push's full stroke ridden to its end: the deviation's handover waits over each stroke
and the settle after its lift-off.

A full stroke ends with the body ahead of the board (the library's ``repush`` entries lift
the pushing foot with the centre of mass 0.15 m/s faster than the deck, which it hands its
momentum to after) and with the deck shaken as the foot leaves the ground (on a held 3 m
circle, seed 0, the deck's roll swung between +0.08 and -0.22 rad in the 0.1 s after a
full stroke's lift-off, at up to 6 rad/s, and was back within 0.05 rad 0.2 s later). Read
against the steady reference's tolerances (the deck's roll 0.01 rad) that is 4-7 times
the handover's bound, and the backup, handed a rider whose body runs ahead of the deck,
kicks the board forward; the MPC, left to ride it (the ``mpc-alone`` controller), rode
every such lift-off out.

So over a re-push's stroke, from its touchdown to :data:`~ridempc.mpc.push_steer.SETTLE`
after its lift-off (the body back over the deck), the state's deviation does not hand over
(as a stroke on a slow board's does, :mod:`~ridempc.mpc.push_handover`); a failed plan or
an infeasible whole-body QP still does, and the deviation is judged again after the settle.
"""

from __future__ import annotations

from ridempc.mpc.push_steer import SETTLE
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["stroke_ending"]


def stroke_ending(
    repushing: bool, reference: MotionReference, t_ref: float, settle: float = SETTLE
) -> bool:
    """Whether the reference's time ``t_ref`` [s] falls between the touchdown of
    ``reference``'s first stroke (a phase with a foot on the ground) and ``settle`` [s]
    after the last phase with a foot off the deck that follows it, during a re-push
    (``repushing``)."""
    if not repushing:
        return False
    start, first, last = 0.0, None, None
    for phase in reference.phases:
        end = start + phase.duration
        if first is None and Contact.GROUND in phase.contacts:
            first = start
        if first is not None and any(c is not Contact.BOARD for c in phase.contacts):
            last = end
        start = end
    return first is not None and last is not None and first <= t_ref < last + settle
