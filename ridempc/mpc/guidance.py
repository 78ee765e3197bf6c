"""Each Hovershoe steered back onto its line: a guidance law on the MPC's heading reference.

A shoe rolls only along its heading, so the MPC moves it sideways only by turning it, and
over its 0.4 s horizon a heading held to within 0.05 rad cannot move it far: the shoes'
sideways drift goes uncorrected, and in turns the rider ends in the splits (the ``pd``
baseline's hip-yaw loop turns a foot that is too far out inwards, hovershoe paper eq.
14-15).

Here each shoe's heading reference is turned towards its line, as in pure pursuit:

.. math::

    e = n^\\top (p - p^*), \\qquad
    \\Delta\\psi = \\operatorname{clip}\\Big(-\\frac{e}{v^* \\tau}, \\pm\\Delta\\psi_{max}\\Big)

with :math:`p` the shoe's estimated position and :math:`p^*` its reference at the
horizon's first node [m], :math:`n` the normal to the reference heading (to the left),
:math:`v^*` the reference speed [m/s] and :math:`\\tau` = ``TAU`` [s]: at speed :math:`v^*`
the heading :math:`\\Delta\\psi` closes the error at :math:`e / \\tau`. The turn is added to
the shoe's heading over the whole horizon; below ``MIN_SPEED`` nothing is turned (the law
would ask for large angles a shoe at rest cannot use). ``TAU`` is the shortest tried that
rode the yaw steps through (``docs/tuning.md``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["MAX_TURN", "MIN_SPEED", "TAU", "steer_onto_lines"]

Array = NDArray[np.float64]
TAU: float = 0.7  # [s] the time to close a sideways error at the reference speed
MAX_TURN: float = 0.15  # [rad] the largest heading turn
MIN_SPEED: float = 0.2  # [m/s] below this reference speed nothing is turned


def steer_onto_lines(
    states: Array,
    x0: Array,
    columns: Sequence[Sequence[int]],
    tau: float = TAU,
    max_turn: float = MAX_TURN,
    min_speed: float = MIN_SPEED,
) -> Array:
    """A copy of the MPC's reference ``states`` (nodes x nx) with each platform's heading
    turned towards its line (module docstring).

    Args:
        states: The reference over the horizon.
        x0: The estimated state (nx), in the same frame.
        columns: Each platform's (x, y, heading, speed) state indices.
        tau: :math:`\\tau` [s].
        max_turn: :math:`\\Delta\\psi_{max}` [rad].
        min_speed: Least reference speed at which a platform is turned [m/s].
    """
    out = np.array(states, dtype=float)
    for x, y, heading, speed in columns:
        v = float(out[0, speed])
        if abs(v) < min_speed:
            continue
        psi = out[0, heading]
        error = -np.sin(psi) * (x0[x] - out[0, x]) + np.cos(psi) * (x0[y] - out[0, y])
        out[:, heading] += float(np.clip(-error / (v * tau), -max_turn, max_turn))
    return out
