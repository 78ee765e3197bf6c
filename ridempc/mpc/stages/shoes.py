"""The Hovershoes' stages' wiring: the observer of where each foot stands along its shoe and
of each shoe's drag (:class:`~ridempc.mpc.shoe_observer.ShoeObserver`, updated every tick
from the whole-body QP's sites and forces), and each shoe's columns in the MPC's state, which
the shoes' problem shaper (:class:`~ridempc.mpc.stages.board_shapers.ShoeLines`) moves."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple, cast

from ridempc.boards.board import Board
from ridempc.boards.canonical import BoardState
from ridempc.mpc.shoe_heading import ShoeHeading
from ridempc.mpc.shoe_observer import ShoeObserver
from ridempc.mpc.stages.base import ControlTick
from ridempc.mpc.stages.board_shapers import ShoeLines
from ridempc.pair_description import Stages
from ridempc.trajopt.platforms import HovershoesBoard, wheeled_board
from ridempc.wbc.model import WholeBodyModel

__all__ = [
    "SHOE_QUANTITIES",
    "ShoeStages",
    "ShoeUpdate",
    "shoe_columns",
    "shoe_observer",
    "shoe_stages",
]

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


class ShoeStages(NamedTuple):
    """A pair's shoe stages (None, or no columns, without the ``shoe_observer`` stage): the
    observer, each shoe's heading from its direction of travel (the soles creep round on
    the pads; the ``shoe_heading`` stage), the lines' problem shaper (each shoe's heading
    turned onto its line with the ``guidance`` stage) and each shoe's columns."""

    observer: ShoeObserver | None
    heading: ShoeHeading | None
    lines: ShoeLines | None
    columns: tuple[tuple[int, ...], ...]


def shoe_stages(
    stages: Stages,
    board: Board | None,
    model: WholeBodyModel,
    platform_feet: Sequence[Sequence[str]],
    columns: Mapping[BoardState, int],
) -> ShoeStages:
    """The shoe stages the pair file's ``stages`` name, for ``board`` (its description, or
    None), the whole-body ``model``, the feet per platform and the MPC's board state
    ``columns``."""
    if board is None or stages.shoe_observer is None:
        return ShoeStages(None, None, None, ())
    observer = shoe_observer(board, model, platform_feet)
    heading = ShoeHeading(observer.platforms) if stages.shoe_heading is not None else None
    shoes = shoe_columns(columns)
    return ShoeStages(observer, heading, ShoeLines(shoes, stages.guidance is not None), shoes)
