"""The interface every rider controller implements.

A controller runs at its own rate (a divisor of the physics rate), reads only a
:class:`~ridempc.sim.sensors.SensorPacket` and the scenario's
:class:`~ridempc.scenarios.Command`, and returns a
:class:`~ridempc.sim.motors.MotorCommand` for the motor drivers.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

if TYPE_CHECKING:
    from ridempc.estimation.state import EstimatedState

__all__ = ["Controller"]


class Controller(ABC):
    """A rider controller.

    Attributes:
        rate_hz: How often :meth:`update` runs [Hz].
        uses_ground_truth: True if it reads ``SensorPacket.truth`` (debugging only).
        command_preview: The command at any time [s], where the ride's commands are planned
            ahead (the simulation sets the scenario's timeline); None when only the
            present command is known. A tracking controller (the MPC) may read the
            reference over its horizon from it; nothing of the robot or board is in it.
        turn_preview: The commanded yaw rate [rad/s] at any time [s] as a path follower
            expects to ask it (the path's turns ahead), or None; for choices made ahead of
            a turn (which foot pushes), not tracked.
    """

    rate_hz: float = 500.0
    uses_ground_truth: bool = False

    def __init__(self, robot: Robot, board: str = "none") -> None:
        self.robot = robot
        self.board = board  # the board's name ("none" on flat ground)
        self.command_preview: Callable[[float], Command] | None = None
        self.turn_preview: Callable[[float], float] | None = None

    def hold_speed(self) -> None:  # noqa: B027 - optional hook
        """Push again while rolling to hold the commanded speed (a scenario's
        ``push_off.hold``); a controller that cannot push ignores it."""

    def reset(self, sensors: SensorPacket) -> None:  # noqa: B027 - optional hook
        """Called once with the first sensor packet, before the first :meth:`update`."""

    @abstractmethod
    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        """One control tick."""

    def standby(self, sensors: SensorPacket, command: Command) -> None:
        """One tick in hot standby (:mod:`ridempc.mpc.handover`): what :meth:`update`
        carries from tick to tick (filters, integrators, its estimator) advanced, its
        command not needed. By default the whole update, its command discarded; a law
        overrides it where the command's own work can be left out, the next update's
        command the same to the bit."""
        self.update(sensors, command)

    def close(self) -> None:  # noqa: B027 - optional hook
        """Called once the ride has ended (also when it fails or is interrupted): end
        whatever the controller started beside the loop (the MPC's solver process)."""

    def diagnostics(self) -> dict[str, float]:
        """Scalars to log at this tick (solve times, modes, ...)."""
        return {}

    def summary(self) -> dict[str, Any]:
        """Figures of the whole ride for ``summary.json`` (solve times, fallbacks, a safe
        hold and why); JSON-serialisable. None by default."""
        return {}

    def estimate(self) -> EstimatedState | None:
        """The controller's latest state estimate, for the judge to log against the truth.

        None for a controller without an estimator (the default), and before its first
        tick. A controller that overrides this is logged with NaN rows until it has one.
        """
        return None
