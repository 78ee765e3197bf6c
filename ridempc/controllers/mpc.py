"""``mpc``: the MPC/WBC rider (:class:`ridempc.mpc.rider.MpcRider`), imported when asked for."""

from __future__ import annotations

from ridempc.controllers.base import Controller
from ridempc.robots.robot import Robot

__all__ = ["make_mpc_rider"]


def make_mpc_rider(robot: Robot, board: str) -> Controller:
    """The MPC rider of ``robot`` on ``board``.

    Raises:
        UnknownNameError: No MPC library for this pair (the message names those that have one).
        ConfigError: The pair's motion library is missing or corrupt.
    """
    from ridempc.mpc.rider import MpcRider

    return MpcRider(robot, board)
