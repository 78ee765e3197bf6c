"""The Hovershoes' stages' wiring: the observer of where each foot stands along its shoe and
of each shoe's drag (:class:`~ridempc.mpc.shoe_observer.ShoeObserver`, updated every tick
from the whole-body QP's sites and forces), and each shoe's columns in the MPC's state, which
the shoes' problem shaper (:class:`~ridempc.mpc.stages.board_shapers.ShoeLines`) moves."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import cast

from ridempc.boards.board import Board
from ridempc.boards.canonical import BoardState
from ridempc.mpc.shoe_observer import ShoeObserver
from ridempc.mpc.stages.base import ControlTick
from ridempc.trajopt.platforms import HovershoesBoard, wheeled_board
from ridempc.wbc.model import WholeBodyModel

__all__ = ["SHOE_QUANTITIES", "ShoeUpdate", "shoe_columns", "shoe_observer"]

# each shoe's quantities that its lines, its foot's place and its drag move, in this order
SHOE_QUANTITIES: tuple[str, ...] = ("x", "y", "heading", "speed")


def shoe_observer(
    board: Board, model: WholeBodyModel, platform_feet: Sequence[Sequence[str]]
) -> ShoeObserver:
    """The shoes' observer of ``board``, each of the whole-body ``model``'s contact sites
    on the shoe its foot stands on (``platform_feet``: the feet per platform; -1: none)."""
    shoes = cast(HovershoesBoard, wheeled_board(board))
    names = model.foot_names
    platform_of = {foot: k for k, group in enumerate(platform_feet) for foot in group}
    sites = [platform_of.get(names[f], -1) for f in model.site_foot]
    return ShoeObserver(shoes, sites)


def shoe_columns(columns: Mapping[BoardState, int]) -> tuple[tuple[int, ...], ...]:
    """Per shoe (platform order), the columns of its :data:`SHOE_QUANTITIES` in the MPC's
    state (``columns``: each board state's)."""
    return tuple(
        tuple(columns[BoardState(k, q)] for q in SHOE_QUANTITIES)
        for k in sorted({state.platform for state in columns})
    )


class ShoeUpdate:
    """The shoes' observer updated after each whole-body QP from its contact sites' places
    and forces (a :class:`~ridempc.mpc.stages.base.TickObserver` of ``wbc_observers``)."""

    def __init__(self, observer: ShoeObserver) -> None:
        self.observer = observer

    def observe(self, tick: ControlTick) -> None:
        out = tick.wbc
        assert out is not None  # after the whole-body QP
        self.observer.update(tick.estimate, out.site_positions, out.site_forces)
