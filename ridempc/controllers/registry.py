"""Controllers by name: the one table the command line and the runner read."""

from __future__ import annotations

from collections.abc import Callable

from ridempc.controllers.base import Controller
from ridempc.controllers.stand import StandController
from ridempc.errors import UnknownNameError
from ridempc.robots.robot import Robot

__all__ = ["CONTROLLERS", "controller_names", "make_controller"]

CONTROLLERS: dict[str, Callable[[Robot], Controller]] = {
    "stand": StandController,
}


def controller_names() -> tuple[str, ...]:
    return tuple(sorted(CONTROLLERS))


def make_controller(name: str, robot: Robot) -> Controller:
    if name not in CONTROLLERS:
        raise UnknownNameError("controller", name, CONTROLLERS)
    return CONTROLLERS[name](robot)
