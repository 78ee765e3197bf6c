"""Boards the robots ride. ``none`` is flat ground; each other board is a folder of ``boards/``."""

from ridempc.boards.board import Board, load_board_file
from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.boards.kinds import BOARD_KINDS, BoardKind, board_kind
from ridempc.boards.parameters import BoardParameters
from ridempc.boards.registry import NO_BOARD, board_names, check_board, load_board, support_height

__all__ = [
    "BOARD_KINDS",
    "NO_BOARD",
    "Board",
    "BoardIO",
    "BoardKind",
    "BoardParameters",
    "Firmware",
    "board_kind",
    "board_names",
    "check_board",
    "load_board",
    "load_board_file",
    "support_height",
]
