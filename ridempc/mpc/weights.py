"""The MPC's weights :math:`Q` and :math:`R` of eq. (19), by Bryson's rule from what each state is.

Each weight is :math:`1 / \\sigma^2` with :math:`\\sigma` the deviation one is willing to
accept, read from tables so that every pair's state layout gets weights without code of its
own: the rider's states by their canonical names (:func:`~ridempc.trajopt.rigid_body.
rigid_body_state_names`, its base's angles ``<base>_roll`` ..., its joints ``q_<joint>``), the
board's by their canonical quantity (:mod:`ridempc.boards.canonical`): the rider's height and
attitude and the deck's roll tightly, the boards' speeds and the platforms' pitch loosely (a
rider that is kept over its feet gets its speed back; on the Hovershoes a board speed held
at 0.02 m/s let the rider tip forward in closed loop), joint angles moderately. Forces are
weighted in units of the robot's weight per contact. Overrides are by exact name.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.canonical import BoardState

__all__ = [
    "BASE_TOLERANCE",
    "BOARD_TOLERANCES",
    "INPUT_TOLERANCES",
    "STATE_TOLERANCES",
    "bryson_weights",
]

Array = NDArray[np.float64]

# The rider's states: (pattern, accepted deviation) in the state's units: [m], [m/s], [rad/s],
# [rad] (first match wins).
STATE_TOLERANCES: tuple[tuple[str, float], ...] = (
    (r"^com_z$", 0.01),
    (r"^com_(x|y)$", 0.05),  # horizontal position
    (r"^v[xyz]$", 0.05),
    (r"^w[xyz]$", 0.3),
    (r"^q_", 0.1),
)
# [rad] the rider's base roll and pitch (``<base>_roll``, ``<base>_pitch``); its yaw as a
# heading's, ``BOARD_TOLERANCES["heading"]``
BASE_TOLERANCE: float = 0.02
# The board's states by quantity (ridempc.boards.canonical), in their units.
BOARD_TOLERANCES: dict[str, float] = {
    "x": 0.05,  # [m] horizontal positions of the platforms
    "y": 0.05,
    "heading": 0.05,  # [rad]
    "roll": 0.01,  # [rad] deck roll: the tracked command (roll RMSE 0.0224 rad at 0.02)
    "pitch": 0.1,  # [rad] platform pitch: the rider leans the platforms to ride
    "speed": 0.1,  # [m/s] loose, the rider's balance comes first
    "pitch_rate": 1.0,  # [rad/s] the boards' fast pitch, yaw and roll rates
    "yaw_rate": 1.0,
    "roll_rate": 1.0,
}
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
    *,
    base: str,
    board_states: Mapping[str, BoardState],
) -> tuple[Array, Array]:
    """Diagonals of :math:`Q` and :math:`R`, :math:`1/\\sigma^2` per name.

    Args:
        state_names: The pair's state names.
        input_names: The pair's input names.
        force_scale: Accepted deviation of a force component [N] (the weight per contact).
        overrides: Weights by exact state or input name (replacing the table's).
        base: The rider's base body, whose Z-Y-X angles are ``<base>_roll`` ... .
        board_states: What each board state is (:attr:`~ridempc.mpc.pairs.MpcPair.
            board_states`).

    Raises:
        KeyError: An override names neither a state nor an input.
    """
    angles = {f"{base}_roll": BASE_TOLERANCE, f"{base}_pitch": BASE_TOLERANCE}
    angles[f"{base}_yaw"] = BOARD_TOLERANCES["heading"]
    sigma = _tolerances(state_names, STATE_TOLERANCES, force_scale)
    for i, name in enumerate(state_names):
        if name in angles:
            sigma[i] = angles[name]
        elif name in board_states:
            sigma[i] = BOARD_TOLERANCES[board_states[name].quantity]
    q = 1.0 / sigma**2
    r = 1.0 / _tolerances(input_names, INPUT_TOLERANCES, force_scale) ** 2
    for name, weight in (overrides or {}).items():
        if name in state_names:
            q[list(state_names).index(name)] = weight
        elif name in input_names:
            r[list(input_names).index(name)] = weight
        else:
            raise KeyError(f"weight override '{name}' names no state or input")
    return q, r
