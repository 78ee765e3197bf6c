"""Board names: ``none`` (flat ground) and every folder of ``boards/`` holding a ``board.toml``."""

from __future__ import annotations

from ridempc.errors import UnknownNameError
from ridempc.paths import boards_dir

__all__ = ["NO_BOARD", "board_names", "check_board"]

NO_BOARD = "none"


def board_names() -> tuple[str, ...]:
    return (NO_BOARD, *sorted(p.parent.name for p in boards_dir().glob("*/board.toml")))


def check_board(name: str) -> str:
    """Return ``name`` if it is a board, else raise :class:`UnknownNameError`."""
    if name not in board_names():
        raise UnknownNameError("board", name, board_names())
    return name
