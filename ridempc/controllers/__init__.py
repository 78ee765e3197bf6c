"""Rider controllers, chosen by name (``ridempc list`` shows them)."""

from ridempc.controllers.base import Controller
from ridempc.controllers.registry import CONTROLLERS, controller_names, make_controller
from ridempc.controllers.stand import StandController

__all__ = ["CONTROLLERS", "Controller", "StandController", "controller_names", "make_controller"]
