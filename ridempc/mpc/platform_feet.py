"""Which feet stand on which of the board's platforms, and which platforms roll under them
as the whole-body QP sees them (:class:`~ridempc.mpc.rider.MpcRider`'s wiring)."""

from __future__ import annotations

from typing import cast

from ridempc.boards.board import Board
from ridempc.boards.hovershoes.parameters import HovershoesParameters
from ridempc.robots.robot import Robot
from ridempc.trajopt.platforms import HovershoesBoard, wheeled_board
from ridempc.trajopt.skateboard import skateboard_model
from ridempc.wbc.platforms import RollingPlatform

__all__ = ["platform_feet", "rolling_platforms"]


def platform_feet(robot: Robot, platforms: int) -> tuple[tuple[str, ...], ...]:
    """Feet per platform: one each when the board has a platform per foot, else all on one."""
    feet = robot.params.foot_bodies
    if platforms == len(feet):
        return tuple((foot,) for foot in feet)
    return (feet,)


def rolling_platforms(board: Board | None) -> tuple[RollingPlatform, ...]:
    """The platforms that the rider's push moves, as the WBC sees them: each Hovershoe, the
    bare shoe with its identified drive (:mod:`ridempc.wbc.platforms`); the skateboard's deck,
    its translating mass with no drive (3.2 kg under a 9 kg dog: taken for ground, the deck
    feet would push it past its plan as the pusher returns); none otherwise."""
    features = board.kind.features if board is not None else frozenset()
    if board is not None and "deck_roll" in features:
        return (RollingPlatform(mass=skateboard_model(board).mass, drive=0.0),)
    if board is None or "shoes" not in features:
        return ()
    shoes = cast(HovershoesBoard, wheeled_board(board))
    params = cast(HovershoesParameters, board.params)
    shoe = RollingPlatform(
        mass=shoes.shoe_mass,
        drive=shoes.reduced.c4,
        tread=params.wheel_width,
        height=params.platform_height,
        twist_damping=shoes.reduced.c3,
    )
    return (shoe,) * shoes.n_platforms
