"""A re-push's full stroke ridden to its end: the deviation waits from the first stroke's
touchdown to the settle after the last foot is back on the deck (ridempc.mpc.push_liftoff)."""

from __future__ import annotations

from ridempc.mpc.push_liftoff import stroke_ending
from ridempc.mpc.push_steer import SETTLE
from ridempc.mpc.reference import select_reference
from ridempc.trajopt.schedule import Contact


def test_the_deviation_waits_over_the_strokes_and_their_settle() -> None:
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    start, first, back = 0.0, None, 0.0
    for phase in reference.phases:
        if first is None and Contact.GROUND in phase.contacts:
            first = start
        start += phase.duration
        if first is not None and any(c is not Contact.BOARD for c in phase.contacts):
            back = start
    assert first is not None and first < back < start  # ends on four feet on the deck
    assert not stroke_ending(True, reference, first - 0.01)  # the swing before: judged
    assert stroke_ending(True, reference, first)
    assert stroke_ending(True, reference, back + SETTLE - 0.01)
    assert not stroke_ending(True, reference, back + SETTLE + 0.01)
    assert not stroke_ending(False, reference, first + 0.1)  # not a re-push: judged
