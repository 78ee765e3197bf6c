"""The command source: what the ride commands over the MPC's horizon.

The scenario (or a path follower) commands a speed, a yaw rate and, on the skateboard, a
deck roll at each instant. The MPC plans over a horizon, so it reads each command at its
horizon's nodes: from the ride's planned commands (the controller's ``command_preview``)
where it has them, else the present command held (or, for the roll, extrapolated at its
rate). On a board steered by its deck's roll (the skateboard) a commanded yaw rate becomes
the roll that steers it and a roll the turn it steers (eq. 14,
:mod:`ridempc.boards.skateboard.steering`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.skateboard.reduced import yaw_rate
from ridempc.boards.skateboard.steering import RollSteering
from ridempc.controllers.base import Controller
from ridempc.mpc.controller import MpcSettings
from ridempc.mpc.manoeuvre import ManoeuvreSelector
from ridempc.scenarios.scenario import Command, Scenario

__all__ = ["CommandHorizon"]

Array = NDArray[np.float64]


class CommandHorizon:
    """The commands over the MPC's horizon, read from the ride's plan where it has one.

    Args:
        owner: The controller whose ``command_preview`` and ``turn_preview`` are read
            (the simulation sets them after the controller is built).
        settings: The MPC's settings (its horizon and step).
        roll_lead: How far ahead of each node the commanded roll is read [s] (the pair's
            ``roll_lead``: the closed loop's lag).
        steers: Whether the rider turns the board itself (else yaw-rate commands are not
            laid over the reference: the Segway's lean turns it).
        steer_gain: The deck's steering gain :math:`K_{board}` [1/m] where the board steers
            by its roll (eq. 14), else None.
        speed_preview: Whether the manoeuvre reads the planned speed a horizon ahead (the
            pair's ``speed_preview``).
    """

    def __init__(
        self,
        owner: Controller,
        settings: MpcSettings,
        roll_lead: float,
        steers: bool,
        steer_gain: float | None,
        speed_preview: bool,
    ) -> None:
        self._owner = owner
        self._settings = settings
        self._roll_lead = roll_lead
        self.steers = steers
        self.steer_gain = steer_gain
        self._speed_preview = speed_preview
        # a yaw-rate command steered by the deck's roll, eq. (14) inverted
        self.roll_steering = RollSteering(gain=steer_gain) if steer_gain is not None else None
        self._command_roll: tuple[float, float] | None = None

    def roll_horizon(self, command: Command, now: float) -> Array:
        """The commanded deck roll at the horizon's nodes [rad], each read the pair's
        ``roll_lead`` ahead (the closed loop's lag): from the ``command_preview`` when the
        ride's commands are planned, else the present command extrapolated at its rate (a
        backward difference over the last MPC step), which tracks a moving command one
        step late."""
        settings = self._settings
        times = now + self._roll_lead + settings.dt * np.arange(settings.horizon + 1)
        planned = self.planned("roll", times)
        if planned is not None:
            return planned
        previous = self._command_roll
        self._command_roll = (now, command.roll)
        rate = 0.0
        if previous is not None and now > previous[0]:
            rate = (command.roll - previous[1]) / (now - previous[0])
        return np.asarray(command.roll + rate * (times - now), dtype=float)

    def steering_roll(self, command: Command, now: float, speed: float) -> Array:
        """The deck roll that steers the commanded yaw rate at the horizon's nodes [rad]
        (:class:`~ridempc.boards.skateboard.steering.RollSteering`, at the board's speed
        :math:`v` [m/s]), each read the pair's ``roll_lead`` ahead as the commanded roll
        is; zero on a board that does not steer by its roll."""
        settings = self._settings
        if self.roll_steering is None:
            return np.zeros(settings.horizon + 1)
        times = now + self._roll_lead + settings.dt * np.arange(settings.horizon + 1)
        rates = self.planned("yaw_rate", times)
        if rates is None:
            rates = np.full(len(times), float(command.yaw_rate))
        return np.array([self.roll_steering.roll(float(w), speed) for w in rates])

    def roll_turn(self, roll: Array, speed: float, names: dict[str, int]) -> Array:
        """The turn a commanded deck roll steers, over the horizon's steps [rad/s]: on the
        skateboard eq. (14), :math:`\\omega_k = -v \\sin\\varphi^*_k / K_{board}` at the
        board's speed :math:`v` (the deck's roll is how it steers); zero elsewhere or
        without a roll command (``names``: the MPC's state columns). Held on the
        reference's heading instead, a rolled deck rolling at 0.5 m/s fought the heading
        and fell in its roll phase."""
        steps = self._settings.horizon
        if self.steer_gain is None or not ManoeuvreSelector.commands_roll(names, roll):
            return np.zeros(steps)
        return np.asarray(yaw_rate(speed, roll[:steps], self.steer_gain), dtype=float)

    def roll_and_turn(
        self,
        command: Command,
        now: float,
        speed: float,
        steering: bool,
        limit: Callable[[Array], Array] | None,
        names: dict[str, int],
    ) -> tuple[Array, Array]:
        """The commanded deck roll at the horizon's nodes [rad] and the turn over its steps
        [rad/s]: the roll commanded, plus, while ``steering`` (balancing, or a re-push with
        no foot on the ground), the roll that steers the commanded yaw rate, held within
        ``limit`` (the stance's, or None); the turn commanded plus the one the roll steers
        at the board's ``speed`` [m/s] (``names``: the MPC's state columns)."""
        roll = self.roll_horizon(command, now)
        if steering:
            roll = roll + self.steering_roll(command, now, speed)
        if limit is not None:
            roll = limit(roll)
        turn = self.yaw_rate_horizon(command, now) + self.roll_turn(roll, speed, names)
        return roll, turn

    def yaw_rate_horizon(self, command: Command, now: float) -> Array:
        """The commanded yaw rate over the horizon's steps [rad/s], read ahead from the
        ``command_preview`` when the ride's commands are planned, else the present one."""
        settings = self._settings
        if not self.steers:
            return np.zeros(settings.horizon)
        planned = self.planned("yaw_rate", now + settings.dt * np.arange(settings.horizon))
        if planned is not None:
            return planned
        return np.full(settings.horizon, float(command.yaw_rate))

    def yaw_rate_ahead(self, command: Command, now: float, window: tuple[float, float]) -> float:
        """The commanded yaw rate [rad/s] averaged over ``window`` [s] from ``now``: as a
        path follower expects to ask it (``turn_preview``), else where the ride's commands
        are planned, else the present one."""
        dt = self._settings.dt
        times = now + window[0] + dt * np.arange(max(1, round((window[1] - window[0]) / dt)))
        turn_preview = self._owner.turn_preview
        if turn_preview is not None:
            return float(np.mean([turn_preview(float(t)) for t in times]))
        planned = self.planned("yaw_rate", times)
        return float(np.mean(planned)) if planned is not None else float(command.yaw_rate)

    def speed_preview_s(self) -> float:
        """How far ahead the manoeuvre reads a planned speed [s]: the MPC's horizon where the
        pair previews it and the ride's commands are planned, else 0
        (:attr:`~ridempc.mpc.pairs.MpcPair.speed_preview`)."""
        if not self._speed_preview or self._owner.command_preview is None:
            return 0.0
        return self._settings.horizon * self._settings.dt

    def speed_command(self, command: Command, now: float) -> Command:
        """``command`` with the speed planned ``speed_preview_s`` ahead."""
        lead = self.speed_preview_s()
        if lead == 0.0:
            return command
        preview = self._owner.command_preview
        assert preview is not None
        ahead = preview(now + lead).velocity
        if ahead == command.velocity:
            return command
        return command.model_copy(update={"velocity": ahead})

    def planned(self, field: str, times: NDArray[np.floating[Any]]) -> Array | None:
        """One field of the ride's planned commands at ``times`` [s] (``command_preview``),
        or None when the commands are not planned ahead."""
        preview = self._owner.command_preview
        if preview is None:
            return None
        timeline = getattr(preview, "__self__", None)
        if isinstance(timeline, Scenario):  # the scenario's own: all the times in one call
            return timeline.command_field_at(field, times)
        return np.array([getattr(preview(float(t)), field) for t in times])
