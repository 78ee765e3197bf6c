"""Canonical names of the quantities in a board's reduced-model state, shared by every board.

Each board's reduced model names its states its own paper's way (the Hovershoes'
``left_psi`` and ``left_v``, the Segway's ``segway_psi`` and ``segway_speed``, the
skateboard's ``board_yaw`` and ``board_v``), and the motion libraries store those names. What
a controller needs is the quantity and the platform: a :class:`BoardState` per state name,
declared by the board's reduced model from its own names (each kind's table of its state
names' quantities), never guessed from a name's ending.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

__all__ = ["QUANTITIES", "BoardState", "board_state_columns", "canonical_board_states"]

# Per platform: its origin [m], heading [rad], forward speed [m/s], pitch [rad] and pitch rate
# [rad/s], yaw rate [rad/s], deck roll [rad] and roll rate [rad/s].
QUANTITIES: tuple[str, ...] = (
    "x",
    "y",
    "heading",
    "speed",
    "pitch",
    "pitch_rate",
    "yaw_rate",
    "roll",
    "roll_rate",
)


class BoardState(NamedTuple):
    """What one board state is: the quantity (:data:`QUANTITIES`) of one platform."""

    platform: int
    quantity: str


def canonical_board_states(
    prefixes: Sequence[str], quantities: Mapping[str, str]
) -> dict[str, BoardState]:
    """Per state name ``<prefix><own name>``, its :class:`BoardState`.

    Args:
        prefixes: Each platform's prefix of its state names, in platform order.
        quantities: The kind's own state names (without prefix) and their quantities.

    Raises:
        ValueError: A quantity not in :data:`QUANTITIES`.
    """
    unknown = sorted(set(quantities.values()) - set(QUANTITIES))
    if unknown:
        raise ValueError(f"board state quantity '{unknown[0]}': allowed: {', '.join(QUANTITIES)}")
    return {
        f"{prefix}{own}": BoardState(k, quantity)
        for k, prefix in enumerate(prefixes)
        for own, quantity in quantities.items()
    }


def board_state_columns(
    state_names: Sequence[str], board_states: Mapping[str, BoardState]
) -> dict[BoardState, int]:
    """Each board state's index in ``state_names`` (those of the board's states it holds)."""
    return {board_states[n]: i for i, n in enumerate(state_names) if n in board_states}
