"""The least speed a re-push's stroke lands on: a coasting board pushed again before it is
slower than a stroke's own speed.

A stroke's impulse along the board, :math:`J = \\int f_x\\,dt` over the pushing foot's
ground time (the library's ``repush`` entries: 4.7 N s for the CyberDog2 at 0.7 m/s), moves
the rider and the board together by

.. math:: v_J = \\frac{J}{m + m_B}

(rider :math:`m`, board :math:`m_B`: 0.39 m/s for the 8.9 kg CyberDog2 on the 3.2 kg
board). A board rolling slower than :math:`v_J` at the touchdown is not kept rolling by the
stroke but started by it: the planted foot drives the body ahead of a deck three times
lighter than it, which the body then drags (on a held 3 m circle the body reached 0.66
m/s over a board slowed to 0.30 and kicked the deck back to -0.14 m/s; the ride fell in
that stroke). The re-push entries are laid for a rolling start.

So a coasting board is pushed again while it will still roll at :math:`v_J` when the
entry's first stroke lands: from its start the entry's weight shift takes
:math:`\\Delta v_e` off the board (the entry's own board speed at its start less at its
first touchdown) and rolling resistance :math:`a_r t_d` over the time :math:`t_d` to the
touchdown,

.. math:: v_{start} = v_J + \\Delta v_e + a_r t_d,

never above the commanded speed (a board at its command coasts).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ridempc.mpc.push_speed import ROLLING_DECELERATION
from ridempc.mpc.reference import MotionReference, select_reference
from ridempc.trajopt.schedule import Contact
from ridempc.trajopt.skate_pair import skate_models

__all__ = ["first_stroke", "least_start", "repush_start", "stroke_speed"]


def first_stroke(reference: MotionReference) -> tuple[float, float] | None:
    """The first phase of ``reference`` with a foot on the ground: its start and end [s]
    (reference time), or None if it has none."""
    start = 0.0
    for phase in reference.phases:
        end = start + phase.duration
        if Contact.GROUND in phase.contacts:
            return start, end
        start = end
    return None


def stroke_speed(reference: MotionReference, rider_mass: float, board_mass: float) -> float:
    """:math:`v_J = J / (m + m_B)` [m/s] of ``reference``'s first stroke, its ground
    contacts' force along the library frame's :math:`x` (the board's heading) summed over
    its steps; 0 without a stroke. ``rider_mass``, ``board_mass``: [kg]."""
    stroke = first_stroke(reference)
    if stroke is None:
        return 0.0
    down, up = stroke
    times = np.asarray(reference.times, dtype=float)[:-1]
    steps = (times >= down - 1e-9) & (times < up - 1e-9)
    impulse = 0.0
    for k in np.flatnonzero(steps):
        for i, contact in enumerate(reference.schedule[k]):
            if contact is Contact.GROUND:
                impulse += float(reference.inputs[k, reference.force_index[i][0]]) * reference.dt
    return impulse / (rider_mass + board_mass)


def least_start(
    reference: MotionReference,
    rider_mass: float,
    board_mass: float,
    speed_column: int,
    deceleration: float = ROLLING_DECELERATION,
) -> float:
    """:math:`v_{start}` [m/s] (module docstring) of the ``repush`` entry ``reference``,
    whose board speed is its state column ``speed_column``; ``deceleration``: :math:`a_r`
    [m/s^2]. 0 for an entry without a stroke."""
    stroke = first_stroke(reference)
    if stroke is None:
        return 0.0
    down = stroke[0]
    speeds = np.asarray(reference.states, dtype=float)[:, speed_column]
    lost = float(speeds[0] - np.interp(down, reference.times, speeds))
    return stroke_speed(reference, rider_mass, board_mass) + max(lost, 0.0) + deceleration * down


@lru_cache(maxsize=32)
def repush_start(robot: str, board: str, target: float, speed_column: int) -> float:
    """:func:`least_start` of the pair's ``repush`` entry for ``target`` [m/s], the robot's
    and the board's masses from their models, the board's speed its state column
    ``speed_column``."""
    reference = select_reference(robot, board, "repush", target)
    rider, deck = skate_models(robot, board)
    return least_start(reference, rider.mass, deck.mass, speed_column)
