"""A re-push is not handed to the balancing backup while a foot is off the deck.

The backup law a rider falls back on (the pair's PD) balances on the feet it stands with on
the board: it has no stroke to finish and no swing to land. Handed a re-push (pushing the
skateboard again from a rolling deck) while the pushing foot is beside the deck, 3-5 cm
above the ground, it drives that foot straight back to its place on the deck, which runs
under the deck's edge: the foot strikes the deck from below, raises that edge and kicks the
3.2 kg board forward while the body keeps its speed (measured, a held 3 m circle, seed 0:
within 10 ms of the handover the pushing hip's abduction torque went from -0.5 to +6 N m, the
foot swept 7 cm inwards under the edge and the deck went 0.47 -> 0.82 m/s in 60 ms; the
rider fell). A re-push on a slowed board drifts from its reference (the entry is laid for a
faster one) and crossed the handover's deviation in both its first strokes.

This is a slow board's: the stroke is timed for the stride's rolling start (its target less
:data:`~ridempc.mpc.manoeuvre.REPUSH_BAND`), and a board slower than that carries the deck
less far past the planted foot, which then lifts beside the deck's middle rather than near
its tail. On a board at or above the rolling start the handover is as before (there, in the
alternating yaw-rate steps, the deferred handover came later and every fall earlier). So
while a re-push on a board slower than its stride's rolling start has a foot off the deck
(on the ground or swinging), the state's
*deviation* from the reference does not hand over; the MPC rides the stroke out and the
deviation is judged again once every foot is back on the deck. A failed plan or an
infeasible whole-body QP still hands over at once: the MPC then has nothing to ride with.
"""

from __future__ import annotations

from collections.abc import Iterable

from ridempc.trajopt.schedule import Contact

__all__ = ["deviation_deferred"]


def deviation_deferred(
    repushing: bool, support: Iterable[Contact] | None, speed: float, rolling_start: float
) -> bool:
    """Whether a deviation beyond the handover's bound waits (see the module docstring):
    during a re-push (``repushing``) on a board slower (``speed`` [m/s]) than the stride's
    ``rolling_start`` [m/s] while any foot's ``support`` (per foot, this MPC step's) is not
    the board."""
    if not repushing or support is None or speed >= rolling_start:
        return False
    return any(contact is not Contact.BOARD for contact in support)
