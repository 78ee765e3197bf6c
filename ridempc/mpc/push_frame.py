"""A stroke's forces in the turned frame: the entry's force reference and the ground's
friction pyramid turned with the reference.

The reference is turned at the commanded yaw rates
(:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.with_turn`): its headings gain
:math:`\\Delta\\psi_k` at node :math:`k`, its centre of mass rides the arc. Its forces are
the entry's, laid out for a board heading along the library frame's :math:`x`; on the deck
the friction pyramids follow the deck's own surface, but a foot on the ground has its
pyramid on the library frame's axes. A pushing foot's entry force sits at the pyramid's
corner, :math:`|f_x| = |f_y| = \\mu f_z` (forward and across the deck at once); a quarter
of the way round a circle (:math:`\\Delta\\psi = 0.84` rad) that force is asked 48 degrees
off the board's axes, nearly all along the board and none across it, and the body,
pushed without the entry's sideways part, twisted off its reference (the trunk's roll and
yaw rates 1.2 rad/s, the CoM's sideways speed 0.2 m/s at the foot's lift-off).

So at each step with a foot on the ground every contact's reference force is turned about
the vertical by :math:`\\Delta\\psi_k`, :math:`f^{ref}_k \\leftarrow R_z(\\Delta\\psi_k)\\,
f^{ref}_k`, and each ground contact's friction pyramid with it, :math:`G_k \\leftarrow G_k
R_z(\\Delta\\psi_k)^T`: the stroke is the entry's stroke in the board's frame. A ride with no
foot on the ground, or not turned, is left as it is.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.friction import ROWS_PER_CONTACT
from ridempc.mpc.problem import MpcProblem
from ridempc.trajopt.schedule import Contact

__all__ = ["step_turns", "with_turned_forces"]

Array = NDArray[np.float64]


def step_turns(rates: Array, turned: float, steps: int, dt: float) -> Array:
    """:math:`\\Delta\\psi_k` [rad] at each of ``steps`` steps: the turn so far ``turned``
    [rad] and the commanded rates ``rates`` [rad/s] integrated over the steps before."""
    rates = np.asarray(rates, dtype=float)
    ahead = np.cumsum(rates[: steps - 1] * dt)
    return turned + np.concatenate([[0.0], ahead])


def with_turned_forces(
    problem: MpcProblem,
    force_index: NDArray[np.int64],
    contacts: Sequence[Sequence[Contact]],
    turns: Array,
) -> MpcProblem:
    """``problem`` with each step's reference forces and its ground contacts' friction
    pyramids turned by ``turns`` [rad] (steps,) where a contact of ``contacts`` (per step,
    per contact) is on the ground (see the module docstring)."""
    ground = np.array([[c is Contact.GROUND for c in step] for step in contacts], dtype=bool)
    pushing = ground.any(axis=1)
    if not pushing.any() or not np.any(np.asarray(turns)[pushing]):
        return problem
    inputs = problem.input_reference.copy()
    matrix = problem.constraint_matrix.copy()
    for k in np.flatnonzero(pushing):
        c, s = np.cos(turns[k]), np.sin(turns[k])
        rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        for i, columns in enumerate(force_index):
            inputs[k, columns] = rotation @ inputs[k, columns]
            if ground[k, i]:
                rows = slice(ROWS_PER_CONTACT * i, ROWS_PER_CONTACT * (i + 1))
                matrix[k, rows][:, columns] = matrix[k, rows][:, columns] @ rotation.T
    return replace(problem, input_reference=inputs, constraint_matrix=matrix)
