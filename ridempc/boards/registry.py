"""Board names: ``none`` (flat ground) and every folder of ``boards/`` holding a ``board.toml``."""

from __future__ import annotations

from ridempc.boards.board import Board, load_board_file
from ridempc.errors import UnknownNameError
from ridempc.paths import boards_dir

__all__ = ["NO_BOARD", "board_names", "check_board", "load_board"]

NO_BOARD = "none"


def board_names() -> tuple[str, ...]:
    return (NO_BOARD, *sorted(p.parent.name for p in boards_dir().glob("*/board.toml")))


def check_board(name: str) -> str:
    """Return ``name`` if it is a board, else raise :class:`UnknownNameError`."""
    if name not in board_names():
        raise UnknownNameError("board", name, board_names())
    return name


def load_board(name: str) -> Board | None:
    """The board of that name, or None for ``none`` (flat ground)."""
    check_board(name)
    if name == NO_BOARD:
        return None
    return load_board_file(boards_dir() / name / "board.toml")


def support_height(name: str) -> float:
    """Height the rider's feet stand at on that board at rest [m]: its decks' top, 0 on the
    ground (the state estimator's first height prior)."""
    board = load_board(name)
    return 0.0 if board is None else board.platform_top
