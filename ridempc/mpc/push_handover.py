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

**A push handed over is blended over the rider's divergence time** (:func:`push_blend`). A
push from outside is ridden by moving the load between the legs: pushed to the left, the
MPC rider (on its whole-body QP's feedforward torques and a tenth of the backup's joint
stiffness) had put 82 N m on the left knee and 7 N m on the right by the impulse stage's
handover, 0.16 s into the push (measured, Hovershoes `hard` seed 151 v0097). The backup
balances with its own, nearly even, feedforward (50/40 N m) and a knee stiffness ten times
the MPC's; switched within the usual blend (0.02 s, 10 ticks), the left knee lost 30 N m
and the right gained 35 N m while their stiffness rose tenfold, the knees rang at ~30 Hz
(+-10 rad/s, +-300 N m) and a foot struck the ground 0.32 s later, where the backup riding
from the start stood the same push. The load a push has shifted is moved back no faster
than the rider's lean grows, over

.. math:: T_{blend} = 1/\\omega = \\sqrt{h/g}

(:func:`~ridempc.mpc.handover.start_window`, ~0.3 s for Cassie's centre of mass 0.9 m over
her feet), the MPC's command faded out and the backup's in over that time. A failed plan or
QP is still blended out within the usual blend: its command cannot be trusted for longer.
"""

from __future__ import annotations

from collections.abc import Iterable

from ridempc.mpc.handover import start_window
from ridempc.trajopt.schedule import Contact

__all__ = ["deviation_deferred", "push_blend"]


def push_blend(com_height: float | None, default: float) -> float:
    """The blend [s] of a push's handover (see the module docstring): the rider's
    divergence time with the centre of mass ``com_height`` [m] over the feet, or
    ``default`` [s] (the handover's own) where that height is not known."""
    return default if com_height is None else max(start_window(com_height), default)


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
