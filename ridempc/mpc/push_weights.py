"""Tighter speed weights over a push-off: the push sets the speed the ride goes on at.

A push-off is an impulse: once the pushing foot leaves the ground, the rider and the board
share the horizontal momentum it gave them (less the rolling drag): the speed the ride
goes on at is set while the foot is down and while the rider settles on the deck after
it. Bryson's weights
(:mod:`ridempc.mpc.weights`) keep the CoM's speed :math:`v_x` within 0.05 m/s and the
board's :math:`v_B` within 0.1 m/s, loosely, so that balance comes first; over a push
that lets each ride's plans take up their own shortfall in the CoM's position instead,
and the push-offs end off their targets by up to about a tenth (``docs/tuning.md``).

So while the ride tracks an entry whose schedule puts a foot on the ground, from the
entry's start to its end, the stage and terminal weights of the states named in the pair's
``push_tolerances`` become :math:`1/\\sigma^2` of those tolerances (:math:`Q_N` = the
pair's terminal factor times :math:`Q`, as always); the rest of the ride keeps its
weights. The board's speed is judged over the entry's last 0.25 s and the next 0.25 s,
after the last stroke, so the weights hold to the entry's end.

They hold up to the pair's ``push_max_target``: on the skateboard 0.7 m/s, the entries of
one to three strokes; the four-stroke push-off to 1.0 m/s, whose last stroke lasts 0.25 s
with the pushing hip at its torque limit, falls in that stroke with them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["pushing", "with_push_weights"]


def pushing(reference: MotionReference, t: float, max_target: float = math.inf) -> bool:
    """Whether ``t`` [s] (reference time) falls within ``reference``, its schedule has a
    foot on the ground (a push-off) and its target is at most ``max_target`` [m/s].

    Before a push-off is commanded the rider holds the start of the lowest entry, at a
    negative reference time: not a push (the rider stands, the weights would fight it).
    """
    if reference.target > max_target or not 0.0 <= t < float(reference.times[-1]):
        return False  # before its start (the rider at rest, waiting) or after its end
    return any(Contact.GROUND in step for step in reference.schedule)


def with_push_weights(
    problem: MpcProblem,
    reference: MotionReference,
    t: float,
    tolerances: Mapping[str, float],
    terminal_factor: float,
    max_target: float = math.inf,
) -> MpcProblem:
    """``problem`` with the named states weighted :math:`1/\\sigma^2` over a push-off.

    Args:
        problem: The tick's problem.
        reference: The reference it tracks (its state names, schedule and length).
        t: The problem's reference time [s].
        tolerances: Accepted deviation :math:`\\sigma` by state name, in the state's units.
        terminal_factor: :math:`Q_N / Q` [-].
        max_target: The largest push-off target they apply to [m/s].

    Returns:
        The problem with the new stage and terminal weights, or ``problem`` itself outside
        a push-off (or one beyond ``max_target``) or without tolerances.

    Raises:
        ValueError: A name that is not a state, or a tolerance that is not positive.
    """
    if not tolerances or not pushing(reference, t, max_target):
        return problem
    names = list(reference.state_names)
    weights = np.array(problem.state_weights, dtype=float)
    for name, sigma in tolerances.items():
        if name not in names:
            raise ValueError(f"push tolerance '{name}' names no state ({', '.join(names)})")
        if not sigma > 0.0:
            raise ValueError(f"push tolerance '{name}' must be positive, got {sigma}")
        weights[names.index(name)] = 1.0 / sigma**2
    return replace(problem, state_weights=weights, terminal_weights=terminal_factor * weights)
