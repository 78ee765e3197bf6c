"""``mpc``: the MPC/WBC rider (:class:`ridempc.mpc.rider.MpcRider`), imported when asked for;
``mpc-alone``: the same rider handing the ride to its PD only on its own failures (a failed
plan, a drop, a whole-body QP on slack), never for a push or a deviation: the ablation that
measures what the MPC rides by itself."""

from __future__ import annotations

from ridempc.controllers.base import Controller
from ridempc.robots.robot import Robot

__all__ = ["make_mpc_alone", "make_mpc_rider"]


def make_mpc_rider(robot: Robot, board: str) -> Controller:
    """The MPC rider of ``robot`` on ``board``.

    Raises:
        UnknownNameError: No MPC library for this pair (the message names those that have one).
        ConfigError: The pair's motion library is missing or corrupt.
    """
    from ridempc.mpc.rider import MpcRider

    return MpcRider(robot, board)


def make_mpc_alone(robot: Robot, board: str) -> Controller:
    """The MPC rider of ``robot`` on ``board`` with no push or deviation handover.

    Raises:
        UnknownNameError: No MPC library for this pair (the message names those that have one).
        ConfigError: The pair's motion library is missing or corrupt.
    """
    from ridempc.mpc.rider import MpcRider

    return MpcRider(robot, board, hands_over_deviations=False)
