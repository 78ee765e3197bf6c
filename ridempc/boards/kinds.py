"""Board kinds: for each, its parameter model, its MuJoCo builder and its firmware.

A kind is a subpackage of :mod:`ridempc.boards` exposing ``KIND``, a :class:`BoardKind`.
The table below maps a kind's name to that subpackage; a board file names its kind.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING, NamedTuple

import mujoco

from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.boards.identification import IdentificationResult
from ridempc.boards.parameters import BoardParameters

if TYPE_CHECKING:
    from ridempc.boards.board import Board
from ridempc.errors import UnknownNameError

__all__ = ["BOARD_KINDS", "BoardKind", "board_kind"]


class BoardKind(NamedTuple):
    """What makes a kind of board.

    Attributes:
        parameters: Its checked parameter model (a :class:`BoardParameters` subclass).
        build: Builds the board's own MuJoCo spec (bodies with free joints, wheel joints,
            motors, the board's sensors, platform sites) from its parameters, unprefixed,
            with the board resting on the ground at the world origin.
        firmware: Makes the board's firmware from its parameters and I/O.
        identify: Identifies the kind's reduced model from simulated experiments on a board.
        features: What the rider meets on this kind of board, by name: ``shoes`` (one
            self-balancing platform per foot, tipping over its wheel's tread), ``knee_bar``
            (a bar the legs push to turn), ``deck_roll`` (a deck that rolls on its trucks
            and steers by its roll). A pair file's stages name the features they need
            (:mod:`ridempc.pair_description`).
    """

    parameters: type[BoardParameters]
    build: Callable[[BoardParameters], mujoco.MjSpec]
    firmware: Callable[[BoardParameters, BoardIO], Firmware]
    identify: Callable[[Board], IdentificationResult]
    features: frozenset[str] = frozenset()


BOARD_KINDS: dict[str, str] = {
    "hovershoes": "ridempc.boards.hovershoes",
    "segway": "ridempc.boards.segway",
    "skateboard": "ridempc.boards.skateboard",
}


def board_kind(name: str) -> BoardKind:
    if name not in BOARD_KINDS:
        raise UnknownNameError("board kind", name, BOARD_KINDS)
    kind: BoardKind = importlib.import_module(BOARD_KINDS[name]).KIND
    return kind
