"""Which of a re-push's nodes steer: the deck's steering roll let go over each stroke and
the weight shift before it, node by node.

The skateboard steers by its deck's roll (eq. 14, :mod:`~ridempc.boards.skateboard.steering`),
and the rider rolls it with her feet on the deck by leaning her body into the turn. A
re-push pushes with the foot on the side away from the turn's centre
(:mod:`~ridempc.mpc.push_side`), and its entry loads that foot by moving the centre of
mass 3 cm towards it across the deck, from a quarter of a second before the foot lands to
the end of its stroke. The two cannot be had at once: a lean into the turn is a body on the
other side of the deck.

Steering was decided for the whole horizon at once by its present node: the horizon
steered while no foot was on the ground, so the plans made in the swing before a stroke
laid the stroke with the deck rolled and the body leaning into the turn, and the rider
landed her pushing foot with her centre of mass 2 cm on the turn's side of the deck instead
of 3 cm on the foot's (the held circle, seed 0). At touchdown the horizon went straight at
once; the MPC, holding the body's lean, planned the pushing foot at a third of the entry's
force, and the strokes gave half of the entry's gain.

So each node's steering roll is scaled by how far it lies from the entry's strokes: not at
all within a stroke, fully from :data:`SETTLE` after it to :data:`WEIGHT_SHIFT` before the
next, linearly in between (the body leaves the lean as the entry shifts it towards the
pushing foot, and leans again as the entry brings it back over the deck). A steering roll
laid on at once at the foot's lift-off, 0.085 rad, moved the reference's balance across the
deck in one step, and the rider was handed over at 4.5 of her tolerances from it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["SETTLE", "WEIGHT_SHIFT", "steering_nodes"]

Array = NDArray[np.float64]

# [s] the library's re-push entries move the centre of mass towards the pushing foot from a
# quarter of a second before it lands (0 to 1.8 cm across the deck by the touchdown, 3.3 cm
# 0.15 s after): the body leaves the turn's lean over this time
WEIGHT_SHIFT: float = 0.25
# [s] and bring it back over the deck's centre line within 3 mm by 0.2 s after the foot
# lifts: the body leans into the turn again over this time
SETTLE: float = 0.2


def steering_nodes(
    reference: MotionReference,
    t_ref: float,
    nodes: int,
    dt: float,
    lead: float = WEIGHT_SHIFT,
    settle: float = SETTLE,
) -> Array:
    """Per node of the horizon from the reference's time ``t_ref`` [s] (``nodes`` nodes
    ``dt`` [s] apart), the share [-] of the steering roll it is given: 0 within a phase of
    ``reference`` with a foot on the ground, 1 from ``settle`` [s] after one to ``lead``
    [s] before the next, linear in between."""
    times = t_ref + dt * np.arange(nodes, dtype=float)
    factor = np.ones(nodes)
    start = 0.0
    for phase in reference.phases:
        end = start + phase.duration
        if Contact.GROUND in phase.contacts:
            before = np.clip((start - times) / lead, 0.0, 1.0)
            after = np.clip((times - end) / settle, 0.0, 1.0)
            factor = np.minimum(factor, np.maximum(before, after))
        start = end
    return factor
