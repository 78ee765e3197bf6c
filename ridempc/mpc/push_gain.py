"""A re-push's speeds laid from the board's own: the push adds what it planned to add.

A ``repush`` entry plans its pushes from the rolling start it was solved for (the board at
its target less :data:`~ridempc.mpc.manoeuvre.REPUSH_BAND`). The board the rider meets at
the first push is slower than that (the switch and rolling resistance take 0.1-0.2 m/s off
it, more on a rolled deck), and a reference that asks the centre of mass for the planned
speed at once has the pushing leg drive the body forward faster than the deck under it:
the deck feet then drag the 3.2 kg deck along (a board at 0.29 m/s kicked to 1.03 m/s
within 0.2 s, and the rider fell). Scaled down instead as a coast is
(:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.coasting`), the push shrinks with the
speed lost, and a slow board is pushed ever more weakly until it stops.

So from the first push on the reference's speeds are *shifted*: with :math:`\\Delta v = v -
v^{ref}_0` the board's speed :math:`v` [m/s] less the reference's at node 0, every node's
forward speed (the centre of mass's along the board's heading and each platform's) gains
:math:`\\Delta v`, and the horizontal places the same speed integrated,
:math:`p_k \\mathrel{+}= \\Delta v \\sum_{j<k} (\\cos\\psi_j, \\sin\\psi_j)\\, \\Delta t`
(:math:`\\psi` the first platform's heading): the push gains over the horizon what the
entry gains there, from wherever the board is.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.problem import MpcProblem

__all__ = ["shifted_speeds"]


def shifted_speeds(problem: MpcProblem, layout: StateLayout, speed: float) -> MpcProblem:
    """``problem`` with its reference's speeds shifted to start at the board's ``speed``
    [m/s] (see the module docstring)."""
    names = layout.names
    platform = layout.prefixes[0]
    states = problem.state_reference.copy()
    board_speed = layout.speed(platform)
    heading = layout.heading(platform)
    if board_speed is None or heading is None:
        return problem
    change = float(speed) - float(states[0, board_speed])
    direction = np.column_stack([np.cos(states[:, heading]), np.sin(states[:, heading])])
    travelled = np.vstack([np.zeros(2), np.cumsum(direction[:-1] * problem.dt, axis=0)])
    for prefix in ("com_", *layout.prefixes):
        states[:, [names[f"{prefix}x"], names[f"{prefix}y"]]] += change * travelled
    states[:, [names["vx"], names["vy"]]] += change * direction
    for prefix in layout.prefixes:
        index = layout.speed(prefix)
        if index is not None:
            states[:, index] += change
    return replace(problem, state_reference=states)
