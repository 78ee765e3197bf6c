"""The MPC's weights :math:`Q` and :math:`R` of eq. (19), by Bryson's rule from state names.

Each weight is :math:`1 / \\sigma^2` with :math:`\\sigma` the deviation one is willing to
accept, read from a table of name patterns (first match wins) so that every pair's state
layout gets weights without code of its own: the rider's height and attitude and the
deck's roll tightly, the boards' speeds and the platforms' pitch loosely (a rider that is
kept over its feet gets its speed back; on the Hovershoes a board speed held at 0.02 m/s
let the rider tip forward in closed loop), joint angles moderately. Forces are weighted in
units of the robot's weight per contact. Overrides are by exact name.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["BASE_TOLERANCE", "INPUT_TOLERANCES", "STATE_TOLERANCES", "bryson_weights"]

Array = NDArray[np.float64]

# (pattern, accepted deviation) in the state's units: [m], [rad], [m/s], [rad/s].
STATE_TOLERANCES: tuple[tuple[str, float], ...] = (
    (r"^com_z$", 0.01),
    (r"_(x|y)$", 0.05),  # horizontal positions of the rider and the board
    (r"_(yaw|psi)$", 0.05),
    (r"_roll$", 0.01),  # deck roll: the tracked command (roll RMSE 0.0224 rad at 0.02)
    (r"_theta$", 0.1),  # platform pitch: the rider leans the platforms to ride
    (r"^v[xyz]$", 0.05),
    (r"_(v|speed)$", 0.1),  # board speed: loose, the rider's balance comes first
    (r"^w[xyz]$", 0.3),
    (r"_(rate|dot)$", 1.0),  # the boards' fast roll, pitch and yaw rates
    (r"^q_", 0.1),
)
# [rad] the rider's base roll and pitch (``<base>_roll``, ``<base>_pitch``), before the table
# (the deck's roll is tracked tighter, the table's ``_roll$``)
BASE_TOLERANCE: float = 0.02
# (pattern, accepted deviation) of the inputs; None: the weight per contact [N].
INPUT_TOLERANCES: tuple[tuple[str, float | None], ...] = (
    (r"^f_", None),
    (r"^qd_", 2.0),  # [rad/s]
    (r".*", 0.2),  # board inputs: the knee bar [rad]
)
_DEFAULT_TOLERANCE = 1.0


def _tolerances(
    names: Sequence[str], table: Sequence[tuple[str, float | None]], force_scale: float
) -> Array:
    out = np.full(len(names), _DEFAULT_TOLERANCE)
    for i, name in enumerate(names):
        for pattern, tolerance in table:
            if re.search(pattern, name):
                out[i] = force_scale if tolerance is None else tolerance
                break
    return out


def bryson_weights(
    state_names: Sequence[str],
    input_names: Sequence[str],
    force_scale: float,
    overrides: Mapping[str, float] | None = None,
    base: str | None = None,
) -> tuple[Array, Array]:
    """Diagonals of :math:`Q` and :math:`R`, :math:`1/\\sigma^2` per name.

    Args:
        state_names: The pair's state names.
        input_names: The pair's input names.
        force_scale: Accepted deviation of a force component [N] (the weight per contact).
        overrides: Weights by exact state or input name (replacing the table's).
        base: The rider's base body, whose roll and pitch take :data:`BASE_TOLERANCE`.

    Raises:
        KeyError: An override names neither a state nor an input.
    """
    angles = [(f"^{re.escape(base)}_(roll|pitch)$", BASE_TOLERANCE)] if base is not None else []
    q = 1.0 / _tolerances(state_names, [*angles, *STATE_TOLERANCES], force_scale) ** 2
    r = 1.0 / _tolerances(input_names, INPUT_TOLERANCES, force_scale) ** 2
    for name, weight in (overrides or {}).items():
        if name in state_names:
            q[list(state_names).index(name)] = weight
        elif name in input_names:
            r[list(input_names).index(name)] = weight
        else:
            raise KeyError(f"weight override '{name}' names no state or input")
    return q, r
