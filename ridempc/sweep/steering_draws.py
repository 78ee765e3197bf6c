"""A yaw-rate command drawn for each variant of a sweep: the ``[steering]`` table of a
distribution. Example::

    [steering]
    yaw_rate = {uniform = [-0.3, 0.3]}       # [rad/s] positive to the left
    t = {uniform = [3.0, 6.0]}               # [s] when the turn is commanded
    duration = {uniform = [1.0, 3.0]}        # [s] how long; then the base's yaw rate again
    ramp = 0.5                               # [s] to the turn's rate and back (not drawn)

The turn is two command events added to the base scenario's: the drawn rate from ``t``, the
base's own rate again from ``t + duration``, each ramped over ``ramp``. A base scenario that
commands yaw rates of its own (events, waves or a path) is refused: the two would fight. A
board that turns only within limits (the skateboard, by its deck roll) has the variant
checked against them (:func:`ridempc.boards.steering.check_steering`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Annotated, Any

from pydantic import Field

from ridempc.scenarios.scenario import Scenario
from ridempc.sweep.laws import Law, Quantity, within
from ridempc.units import MAX_DURATION, CheckedModel, Real

__all__ = ["SteeringDraws", "own_yaw_commands", "turn_events"]

# The scenarios' own bound on a yaw rate: two turns a second.
YawRate = Annotated[Quantity, within(-4.0 * math.pi, 4.0 * math.pi, "rad/s")]
TurnTime = Annotated[Quantity, within(0.0, MAX_DURATION, "s")]
TurnDuration = Annotated[Quantity, within(0.0, MAX_DURATION, "s", low_open=True)]


class SteeringDraws(CheckedModel):
    """A turn at a drawn yaw rate for a drawn while (module docstring).

    Attributes:
        yaw_rate: The commanded turning rate, positive to the left [rad/s].
        t: When it is commanded [s].
        duration: How long it is held [s].
        ramp: How long the command takes to reach the rate, and to return [s].
    """

    yaw_rate: YawRate
    t: TurnTime
    duration: TurnDuration = Law(fixed=2.0)
    # Half a second: the library's yaw-steps step at once, a sweep's turn should not be a jolt.
    ramp: Annotated[Real, Field(ge=0.0, le=5.0)] = 0.5

    def quantities(self) -> dict[str, Law]:
        """The laws by dotted name, in drawing order."""
        names = ("yaw_rate", "t", "duration")
        return {f"steering.{name}": getattr(self, name) for name in names}

    def latest_end(self) -> float:
        """The latest the turn can end, its return ramp included [s]."""
        return self.t.bounds()[1] + self.duration.bounds()[1] + self.ramp


def own_yaw_commands(scenario: Scenario) -> str | None:
    """The first field by which ``scenario`` commands a yaw rate of its own, or None."""
    for i, event in enumerate(scenario.commands):
        if event.yaw_rate not in (None, 0.0):
            return f"commands.{i}.yaw_rate"
    for j, wave in enumerate(scenario.waves):
        if wave.field == "yaw_rate":
            return f"waves.{j}"
    return "path" if scenario.path is not None else None


def turn_events(
    steering: SteeringDraws, commands: list[dict[str, Any]], values: Mapping[str, float]
) -> list[dict[str, Any]]:
    """The base's command events (dumped) with the turn's two added, in time order (the
    turn's after a base event at the same time)."""
    start = values["steering.t"]
    rate = values["steering.yaw_rate"]
    end = start + values["steering.duration"]
    turn = [
        {"t": start, "ramp": steering.ramp, "yaw_rate": rate},
        {"t": end, "ramp": steering.ramp, "yaw_rate": 0.0},
    ]
    return sorted([*commands, *turn], key=lambda event: event["t"])
