"""Controllers by name: the one table the command line and the runner read."""

from __future__ import annotations

from collections.abc import Callable

from ridempc.controllers.base import Controller
from ridempc.controllers.mpc import make_mpc_alone, make_mpc_rider
from ridempc.controllers.pd import make_pd_baseline
from ridempc.controllers.stand import StandController
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.robots.robot import Robot

__all__ = ["CONTROLLERS", "DEAD_WEIGHT", "NO_ROBOT", "controller_names", "make_controller"]

NO_ROBOT = "none"  # the robot name of a board ridden by a dead weight
DEAD_WEIGHT = "dead-weight"  # the controller of a dead weight: none at all

# name -> factory(robot, board name)
CONTROLLERS: dict[str, Callable[[Robot, str], Controller]] = {
    "stand": StandController,
    "pd": make_pd_baseline,
    "mpc": make_mpc_rider,
    "mpc-alone": make_mpc_alone,
}


def controller_names() -> tuple[str, ...]:
    return (*sorted(CONTROLLERS), DEAD_WEIGHT)


def make_controller(name: str, robot: Robot | None, board: str = "none") -> Controller | None:
    """The named controller for ``robot`` on ``board``; None for a dead weight.

    Raises:
        UnknownNameError: No such controller.
        ConfigError: A dead weight with a controller, or a robot with ``dead-weight``.
    """
    if name not in controller_names():
        raise UnknownNameError("controller", name, controller_names())
    if robot is None or name == DEAD_WEIGHT:
        if robot is not None or name != DEAD_WEIGHT:
            raise ConfigError(
                f"controller '{DEAD_WEIGHT}' goes with robot '{NO_ROBOT}' and only with it"
            )
        return None
    return CONTROLLERS[name](robot, board)
