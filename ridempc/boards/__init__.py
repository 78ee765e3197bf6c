"""Boards the robots ride. ``none`` is flat ground; each other board is a folder of ``boards/``."""

from ridempc.boards.registry import NO_BOARD, board_names, check_board

__all__ = ["NO_BOARD", "board_names", "check_board"]
