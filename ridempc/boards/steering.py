"""What a board can steer: the yaw-rate limits of its rider, and the scenario checked
against them before a ride.

Only the skateboard limits its turns here: it steers by its deck roll, within the roll the
stance holds and above a least speed (:mod:`ridempc.boards.skateboard.steering`). The
Hovershoes and the Segway turn under the rider's feet or bar at any speed; their yaw rates
are bounded by the scenario's own field checks.
"""

from __future__ import annotations

import numpy as np

from ridempc.boards.board import Board
from ridempc.boards.skateboard.parameters import SkateboardParameters
from ridempc.boards.skateboard.steering import RollSteering
from ridempc.errors import ConfigError
from ridempc.scenarios.path import CirclePath
from ridempc.scenarios.scenario import Scenario

__all__ = ["WAVE_SAMPLE", "check_steering", "steering_limits"]

WAVE_SAMPLE: float = 0.05  # [s] a yaw-rate wave is checked this often (its period >= 0.1 s)


def steering_limits(board: Board | None) -> RollSteering | None:
    """The board's steering map, where its turns are limited; None elsewhere."""
    if board is not None and isinstance(board.params, SkateboardParameters):
        return RollSteering.of(board.params)
    return None


def check_steering(scenario: Scenario, board: Board | None) -> None:
    """Refuse a steering command the board cannot turn: a yaw rate below the least speed
    or beyond the roll the stance holds, a path tighter than the board turns.

    Raises:
        ConfigError: Naming the scenario, the field and the value, and what is allowed.
    """
    limits = steering_limits(board)
    if limits is None:
        return
    name = f"scenario '{scenario.name}'"
    for i, event in enumerate(scenario.commands):
        t = event.t + event.ramp
        command = scenario.command_at(t)
        field = "yaw_rate" if event.yaw_rate is not None else "velocity"
        limits.check_command(command.yaw_rate, command.velocity, f"{name}: commands.{i}.{field}")
    for j, wave in enumerate(scenario.waves):
        if wave.field not in ("yaw_rate", "velocity"):
            continue
        end = min(wave.stop, scenario.duration)
        for t in np.arange(wave.start, end + WAVE_SAMPLE, WAVE_SAMPLE):
            command = scenario.command_at(float(min(t, end)))
            limits.check_command(command.yaw_rate, command.velocity, f"{name}: waves.{j}")
    path = scenario.path
    if path is None:
        return
    if isinstance(path, CirclePath):
        limits.check_radius(path.radius, f"{name}: path.radius")
    else:
        limits.check_radius(1.0 / path.max_curvature, f"{name}: path.offset (the turn at a gate)")
    speed = scenario.command_at(path.start).velocity
    if abs(speed) < limits.min_speed:
        raise ConfigError(
            f"{name}: path.start {path.start:g} s at velocity {speed:g} m/s; allowed: a path "
            f"followed at |velocity| >= {limits.min_speed:g} m/s (the skateboard steers by "
            "its deck roll)"
        )
