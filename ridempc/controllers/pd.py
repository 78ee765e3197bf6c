"""``pd``: the papers' PD baselines, one per kind of robot and kind of board.

The baseline for a ride is looked up in :data:`PD_BASELINES` by (robot kind, board kind) and
imported on use (the baselines import :mod:`ridempc.controllers.base`, so an eager import here
would be circular).
"""

from __future__ import annotations

from importlib import import_module

from ridempc.boards import NO_BOARD, load_board
from ridempc.controllers.base import Controller
from ridempc.errors import ConfigError
from ridempc.robots.robot import Robot

__all__ = ["PD_BASELINES", "make_pd_baseline"]

# (robot kind, board kind) -> "module:Class"
PD_BASELINES: dict[tuple[str, str], str] = {
    ("biped", "none"): "ridempc.baselines.cassie_standing:CassieStanding",
    ("biped", "hovershoes"): "ridempc.baselines.cassie_hovershoes:CassieHovershoes",
    ("biped", "segway"): "ridempc.baselines.cassie_segway:CassieSegway",
    ("quadruped", "none"): "ridempc.baselines.quadruped_skateboard:QuadrupedSkateboardPD",
    ("quadruped", "skateboard"): "ridempc.baselines.quadruped_skateboard:QuadrupedSkateboardPD",
}


def make_pd_baseline(robot: Robot, board: str) -> Controller:
    """The PD baseline for ``robot`` riding ``board``.

    Raises:
        ConfigError: No baseline exists for this kind of robot on this kind of board.
    """
    loaded = load_board(board)
    board_kind = loaded.params.kind if loaded is not None else NO_BOARD
    key = (robot.params.kind, board_kind)
    if key not in PD_BASELINES:
        known = ", ".join(f"{r} on {b}" for r, b in sorted(PD_BASELINES))
        raise ConfigError(
            f"no PD baseline for a {key[0]} ({robot.name}) on {board} (there are: {known})"
        )
    module, name = PD_BASELINES[key].split(":")
    controller: Controller = getattr(import_module(module), name)(robot, board)
    return controller
