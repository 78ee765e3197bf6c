"""Rider controllers, chosen by name (``ridempc list`` shows them)."""

from ridempc.controllers.base import Controller
from ridempc.controllers.registry import (
    CONTROLLERS,
    DEAD_WEIGHT,
    NO_ROBOT,
    controller_names,
    make_controller,
)
from ridempc.controllers.stand import StandController

__all__ = [
    "CONTROLLERS",
    "DEAD_WEIGHT",
    "NO_ROBOT",
    "Controller",
    "StandController",
    "controller_names",
    "make_controller",
]
