"""A re-push makes up the speed it has fallen behind its entry, while a foot is on the ground.

From the first push on, a re-push's reference is shifted to start at the board's speed
(:mod:`.push_gain`): each tick asks the strokes to gain what the entry plans to gain over
the horizon, from wherever the board is. A stroke that falls short is never asked back: the
next tick starts from the slower board, and the pair slows stroke by stroke: in a turn,
where the strokes fall short, a held circle's board slowed to near rest within two strides.

Only the pushing foot on the ground can add to the momentum the rider and the board share;
the feet on the deck only move it between them. So the lag is asked back over the ground
time alone: with :math:`\\delta = \\min(\\max(v^{ref}_0 - v, 0), \\delta_{max})` the
board's lag behind the entry at node 0 [m/s], :math:`g_k` the ground time [s] of the
horizon's steps before node :math:`k` and :math:`G` the entry's ground time left [s], node
:math:`k`'s speeds gain

.. math:: c_k = \\delta \\min(g_k / G, 1)

on top of the shift: the strokes left in the entry make the lag up by their end, and
between strokes (and after the last) the reference coasts as the entry does. Asked over the
whole horizon instead, the lag is made up by the deck feet driving the deck against the
body, which outruns the board and falls off its front (``docs/tuning.md``).

Only a board below the entry's rolling start (its target less
:data:`~ridempc.mpc.manoeuvre.REPUSH_BAND`) is behind its strokes: they are laid for a
board rolling at that speed, and ridden from it (straight, or in alternating turns) they
gain what they plan. So the lag asked back is at most how far the board is below that
start (:func:`stroke_catch_up`), which fades it out continuously as the board reaches it;
asked of faster boards too, a stroke at 0.5-0.6 m/s drove the body 0.3 m/s ahead of the
deck in 0.3 s, and the handover that followed kicked the board.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["MAX_CATCH_UP", "catch_up", "ground_time_left", "stroke_catch_up"]

Array = NDArray[np.float64]

# [m/s] the most of a lag a re-push asks back: one stride's planned gain
# (ridempc.trajopt.skate_pair.REPUSH_GAIN), so the strokes are asked at most twice what the
# entry was solved for; a larger lag (a board near rest) is not the strokes' to make up
MAX_CATCH_UP: float = 0.2


def ground_time_left(reference: MotionReference, t: float) -> float:
    """The time [s] a foot is on the ground in ``reference``'s schedule from ``t`` [s]
    (reference time) to its end."""
    first = max(int(np.floor((t - float(reference.times[0])) / reference.dt + 1e-9)), 0)
    ground = sum(1 for step in reference.schedule[first:] if Contact.GROUND in step)
    return reference.dt * ground


def catch_up(problem: MpcProblem, lag: float, ground_left: float) -> Array:
    """The speed :math:`c_k` [m/s] each of ``problem``'s nodes gains on top of the shift
    (see the module docstring).

    Args:
        problem: The tick's problem: its step and per-step contacts.
        lag: The board's speed behind the entry's at node 0, :math:`v^{ref}_0 - v` [m/s].
        ground_left: :math:`G`, the entry's ground time left [s] (:func:`ground_time_left`).

    Returns:
        :math:`c_k`, k = 0..N; zeros with no lag, no ground time left or no contacts known.
    """
    nodes = len(problem.state_reference)
    lag = min(max(float(lag), 0.0), MAX_CATCH_UP)
    if lag == 0.0 or ground_left <= 0.0 or not problem.contacts:
        return np.zeros(nodes)
    ground = np.array([Contact.GROUND in step for step in problem.contacts], dtype=float)
    elapsed = np.concatenate([[0.0], np.cumsum(ground * problem.dt)])
    elapsed = np.pad(elapsed[:nodes], (0, max(nodes - len(elapsed), 0)), mode="edge")
    return lag * np.minimum(elapsed / ground_left, 1.0)


def stroke_catch_up(
    problem: MpcProblem,
    layout: StateLayout,
    reference: MotionReference,
    t: float,
    speed: float,
    rolling_start: float,
) -> Array:
    """:func:`catch_up` of a re-push's tick: the lag of the board's ``speed`` [m/s] behind
    ``problem``'s reference at node 0, but no more than it is below the entry's
    ``rolling_start`` [m/s], made up over ``reference``'s ground time left from ``t`` [s]
    (reference time)."""
    board_speed = layout.speed(layout.prefixes[0])
    if board_speed is None:
        return np.zeros(len(problem.state_reference))
    lag = float(problem.state_reference[0, board_speed]) - float(speed)
    below = float(rolling_start) - float(speed)
    return catch_up(problem, min(lag, below), ground_time_left(reference, t))
