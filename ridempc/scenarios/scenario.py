"""Scenarios: a ride's duration, its command timeline, disturbances, noise and parameter changes.

A scenario is a small TOML file, validated on load (unknown keys, wrong types and
non-physical values are refused with the field named). Example::

    name = "push"
    description = "Stand, take a 60 N push on the base for 0.2 s at t = 3 s."
    duration = 10.0            # [s]

    [[commands]]               # piecewise constant, optionally ramped
    t = 0.0                    # [s]
    velocity = 0.0             # forward speed [m/s]
    yaw_rate = 0.0             # [rad/s]

    [[disturbances]]
    t = 3.0                    # [s]
    body = "base"              # "base", or a body name of the robot or board
    force = [60.0, 0.0, 0.0]   # world frame [N]
    duration = 0.2             # [s]

    [path]                     # a path to follow, see ridempc.scenarios.path
    kind = "circle"            # or "slalom"
    start = 6.5                # [s] laid from the rider's pose then
    entry = 1.0                # [m] ahead of her
    radius = 3.0               # [m], positive turning left

    [noise]                    # sensor noise overrides, see SensorNoise
    vio_latency = 0.05

    [[changes]]                # one knob of ridempc.sim.knobs.KNOBS each
    t = 5.0                    # [s]; 0 (the default): before the first physics step
    parameter = "floor_friction"
    value = 0.3                # [-], in (0, 3]

    [[changes]]
    parameter = "board_mass"
    body = "left_shoe"         # a body of the board
    scale = 1.3                # times the nominal mass; exactly one of value, scale

    [[changes]]
    parameter = "payload"
    body = "base"              # "base", or a body of the robot
    mass = 5.0                 # [kg]
    offset = [0.0, 0.0, 0.1]   # in the body's frame [m]

    [[changes]]
    parameter = "firmware_gain"
    gain = "pitch_kp"          # Hovershoes: pitch_kp, pitch_kd, tilt_back_gain; Segway: [gains]
    scale = 0.8

The other knobs: ``tyre_friction``, ``deck_friction`` [-], ``wheel_radius`` [m],
``bushing_stiffness`` [N m/rad] and ``bushing_damping`` [N m s/rad] (skateboard),
``base_payload`` [kg], ``motor_torque_limit`` (scale only) and ``joint_damping``
[N m s/rad] (``joint``, default all); units, ranges and how each applies are in
:mod:`ridempc.sim.knobs`.

Terrain (slopes, steps, stairs, rough patches, raised strips, boxes) is a list of
``[[terrain]]`` tables, described in :mod:`ridempc.scenarios.terrain`.
"""

from __future__ import annotations

import math
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, field_validator, model_validator

from ridempc.errors import ConfigError
from ridempc.robots.kind import RobotKind, robot_kind
from ridempc.scenarios.path import PathCommand
from ridempc.scenarios.terrain import TerrainItem, check_terrain
from ridempc.sim.knobs import KNOBS, PAYLOAD_OFFSET_MAX, SCALE_MAX
from ridempc.sim.sensors import SensorNoise
from ridempc.tomlfile import load_checked
from ridempc.units import MAX_DURATION, CheckedModel, Duration, Flag, Real, RideDuration, Time

__all__ = [
    "Command",
    "CommandEvent",
    "CommandWave",
    "Disturbance",
    "PUSH_OFF_WINDOW",
    "ParameterChange",
    "PushOff",
    "Scenario",
    "load_scenario_file",
]

# Command bounds: beyond what any board carries a rider at (the Segway's 4.44 m/s top speed,
# a spin of 2 turns a second, a stance change of half a metre, the skateboard's 0.5 rad roll
# limit), so a value outside them is a typo, not an experiment.
Velocity = Annotated[Real, Field(ge=-10.0, le=10.0, description="[m/s]")]
YawRate = Annotated[Real, Field(ge=-4.0 * math.pi, le=4.0 * math.pi, description="[rad/s]")]
LateralOffset = Annotated[Real, Field(ge=-0.5, le=0.5, description="[m]")]
Roll = Annotated[Real, Field(ge=-0.5, le=0.5, description="[rad]")]
# A push or kick: 10 kN (or 100 N/kg, ten g) throws any of the robots; more is a typo.
Force = Annotated[Real, Field(ge=-10_000.0, le=10_000.0, description="[N] or [N/kg]")]
Torque = Annotated[Real, Field(ge=-2_000.0, le=2_000.0, description="[N m] or [N m/kg]")]
# A foot or platform moved by more than half a metre is off any deck.
Offset = Annotated[Real, Field(ge=-0.5, le=0.5, description="[m]")]
Vector3 = tuple[Force, Force, Force]
TorqueVector = tuple[Torque, Torque, Torque]


class _Frozen(CheckedModel):
    """The scenario's models: strict numbers, no NaN, no unknown keys, immutable."""


class Command(_Frozen):
    """What the rider is asked to do at one instant.

    Attributes:
        velocity: Forward speed in the heading frame [m/s].
        yaw_rate: Turning rate [rad/s], positive to the left.
        lateral_offset: Change of each foot's lateral distance from the centre line, about the
            stance (the hovershoe paper's :math:`y_{offset}` minus its nominal value) [m]; the
            feet are :math:`2 \times` this further apart.
        roll: Board roll reference [rad].
    """

    velocity: Velocity = 0.0
    yaw_rate: YawRate = 0.0
    lateral_offset: LateralOffset = 0.0
    roll: Roll = 0.0


_COMMAND_DEFAULTS: MappingProxyType[str, float] = MappingProxyType(Command().model_dump())


class CommandEvent(_Frozen):
    """From time ``t``, set the given command fields (ramped over ``ramp`` seconds)."""

    t: Time
    ramp: Annotated[Time, Field(description="[s]")] = 0.0
    velocity: Velocity | None = None
    yaw_rate: YawRate | None = None
    lateral_offset: LateralOffset | None = None
    roll: Roll | None = None

    def fields(self) -> dict[str, float]:
        return dict(self._fields)

    @cached_property
    def _fields(self) -> dict[str, float]:
        """The fields it sets, once (:meth:`Scenario.command_at` reads them every tick)."""
        return {
            k: v for k, v in self.model_dump().items() if k not in ("t", "ramp") and v is not None
        }


class CommandWave(_Frozen):
    r"""A sinusoid added to one command field between ``start`` and ``stop``:
    :math:`a \sin(2\pi (t - t_0) / T)` (the skateboard's roll reference, the wave pattern)."""

    field: Literal["velocity", "yaw_rate", "lateral_offset", "roll"]
    amplitude: Annotated[Real, Field(ge=-10.0, le=10.0)]  # the field's unit; the widest bound
    period: Duration
    start: Time = 0.0
    stop: Duration = MAX_DURATION

    def value(self, t: float) -> float:
        if not self.start <= t < self.stop:
            return 0.0
        return self.amplitude * math.sin(2.0 * math.pi * (t - self.start) / self.period)


class Disturbance(_Frozen):
    """A force (and torque) applied to a body for a while: a push or a kick."""

    t: Time
    body: str = "base"
    force: Vector3 = (0.0, 0.0, 0.0)  # world frame [N]
    torque: TorqueVector = (0.0, 0.0, 0.0)  # world frame [N m]
    duration: Annotated[Real, Field(gt=0.0, le=5.0)] = 0.1  # [s]; a longer one is a load
    per_kg: Flag = False  # force and torque are per kg of the robot's mass [N/kg], [N m/kg]


class ParameterChange(_Frozen):
    """A change of a physical parameter at time ``t``: one knob of
    :data:`ridempc.sim.knobs.KNOBS`, set to ``value`` or to ``scale`` times its nominal
    value (exactly one of them; ``payload`` takes ``mass`` and ``offset`` instead).

    Attributes:
        t: When it takes effect [s] (0: before the first physics step).
        parameter: The knob's name.
        value: The new value [the knob's unit].
        scale: The new value over the nominal one [-].
        body: Where a ``board_mass`` (a board body) or ``payload`` (a rider body, ``base``
            for the base) applies.
        gain: Which firmware gain ``firmware_gain`` sets.
        joint: The one robot joint ``joint_damping`` sets (default: all of them).
        mass: The payload's mass [kg].
        offset: The payload's position in the body's frame [m].
    """

    t: Time = 0.0
    parameter: str
    value: Real | None = None
    scale: Real | None = None
    body: str | None = None
    gain: str | None = None
    joint: str | None = None
    mass: Real | None = None
    offset: tuple[Real, Real, Real] | None = None

    @field_validator("parameter")
    @classmethod
    def _known(cls, name: str) -> str:
        if name not in KNOBS:
            raise ValueError(f"unknown knob '{name}' (valid: {', '.join(sorted(KNOBS))})")
        return name

    @model_validator(mode="after")
    def _in_range(self) -> ParameterChange:
        knob = KNOBS[self.parameter]
        given = [f for f in ("value", "scale") if getattr(self, f) is not None]
        if knob.forms and len(given) != 1:
            raise ValueError(
                f"{self.parameter} takes exactly one of "
                f"{' or '.join(f for f in ('value', 'scale') if f in knob.forms)}"
            )
        for form in given:
            if form not in knob.forms:
                raise ValueError(f"{self.parameter} takes no {form}")
        if self.value is not None and not knob.admits(self.value):
            raise ValueError(f"{self.parameter} value = {self.value} is outside {knob.allowed()}")
        if self.scale is not None and not (
            0.0 < self.scale <= SCALE_MAX and (knob.forms != {"scale"} or knob.admits(self.scale))
        ):
            top = knob.high if knob.forms == {"scale"} else SCALE_MAX
            raise ValueError(f"{self.parameter} scale = {self.scale} is outside (0, {top:g}]")
        for name in ("body", "gain", "joint"):
            if getattr(self, name) is not None and knob.where != name:
                raise ValueError(f"{self.parameter} takes no {name}")
        if knob.where is not None and knob.where_required and getattr(self, knob.where) is None:
            raise ValueError(f"{self.parameter} needs a {knob.where}")
        payload = self.parameter == "payload"
        if not payload and (self.mass is not None or self.offset is not None):
            raise ValueError(f"{self.parameter} takes no mass or offset (a payload does)")
        if payload:
            if self.mass is None:
                raise ValueError(f"payload needs a mass in {knob.allowed()}")
            if not knob.admits(self.mass):
                raise ValueError(f"payload mass = {self.mass} is outside {knob.allowed()}")
            offset = self.offset or (0.0, 0.0, 0.0)
            if not all(math.isfinite(x) and abs(x) <= PAYLOAD_OFFSET_MAX for x in offset):
                raise ValueError(
                    f"payload offset = {list(offset)} is outside [-{PAYLOAD_OFFSET_MAX:g}, "
                    f"{PAYLOAD_OFFSET_MAX:g}] m per axis"
                )
        return self


class PushOff(_Frozen):
    """A push-off from rest to a target speed (skateboard paper, the acceleration mode).

    The ride's summary adds ``target_velocity`` and ``final_velocity``: the board's mean
    horizontal speed over :math:`t_j \\pm` ``PUSH_OFF_WINDOW``/2, with :math:`t_j` =
    ``judged_at``, the end of the push-off (a rolling board slows afterwards).
    """

    target: Annotated[Real, Field(gt=0.0, le=10.0)]  # [m/s], at most a command's speed
    judged_at: Time  # [s]
    # push again while rolling, holding the commanded speed against rolling resistance (the
    # library's ``repush`` entries); off, the board coasts after the push-off, as the paper's
    hold: bool = False


PUSH_OFF_WINDOW: float = 0.5  # [s]


class Scenario(_Frozen):
    """A checked, immutable scenario."""

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9._-]*$")
    description: str = ""
    duration: RideDuration
    robots: tuple[str, ...] = ()  # robots it applies to; empty means any
    # kinds of robot it applies to (robot.toml's `kind`: biped, quadruped); empty means any
    robot_kinds: tuple[RobotKind, ...] = ()
    boards: tuple[str, ...] = ()  # boards it applies to; empty means any
    metrics_start: Time = 0.0  # tracking errors are measured from this time on [s]
    foot_offset: tuple[Offset, Offset] = (0.0, 0.0)  # feet off the platform centre, (x, y) [m]
    platform_offsets: tuple[tuple[Offset, Offset], ...] = ()  # independent platforms moved [m]
    commands: tuple[CommandEvent, ...] = ()
    waves: tuple[CommandWave, ...] = ()
    disturbances: tuple[Disturbance, ...] = ()
    changes: tuple[ParameterChange, ...] = ()
    noise: SensorNoise = SensorNoise()
    push_off: PushOff | None = None
    terrain: tuple[TerrainItem, ...] = ()  # [[terrain]]: see ridempc.scenarios.terrain
    path: PathCommand | None = None  # a path to follow (ridempc.scenarios.path)

    @model_validator(mode="after")
    def _terrain_fits(self) -> Scenario:
        check_terrain(self.terrain)
        return self

    @model_validator(mode="after")
    def _ordered(self) -> Scenario:
        times = [c.t for c in self.commands]
        if times != sorted(times):
            raise ValueError("commands must be in time order")
        for i, wave in enumerate(self.waves):
            if wave.stop <= wave.start:
                raise ValueError(f"waves.{i}: stop ({wave.stop} s) must come after start")
        return self

    @model_validator(mode="after")
    def _within_the_ride(self) -> Scenario:
        """An event after the end would never happen: a mistake, not a no-op to ignore."""
        times = [("metrics_start", self.metrics_start)]
        times += [(f"commands.{i}.t", c.t) for i, c in enumerate(self.commands)]
        times += [(f"waves.{i}.start", w.start) for i, w in enumerate(self.waves)]
        times += [(f"disturbances.{i}.t", d.t) for i, d in enumerate(self.disturbances)]
        times += [(f"changes.{i}.t", c.t) for i, c in enumerate(self.changes)]
        if self.push_off is not None:
            times.append(("push_off.judged_at", self.push_off.judged_at))
        if self.path is not None:
            times.append(("path.start", self.path.start))
        for where, t in times:
            if t > self.duration or (where == "metrics_start" and t >= self.duration):
                raise ValueError(
                    f"{where} = {t} s is after the end of the ride (duration {self.duration} s)"
                )
        return self

    def applies_to(self, robot: str, board: str) -> bool:
        return (
            (not self.robots or robot in self.robots)
            and (not self.robot_kinds or robot_kind(robot) in self.robot_kinds)
            and (not self.boards or board in self.boards)
        )

    def command_at(self, t: float) -> Command:
        """The command in force at time ``t`` [s] (piecewise constant, linear ramps).

        Called several times a control tick, it builds the command from the events' checked
        values without validating them again (``model_construct``).
        """
        values = dict(_COMMAND_DEFAULTS)
        for event in self.commands:
            if event.t > t:
                break
            for key, target in event._fields.items():
                if event.ramp > 0.0 and t < event.t + event.ramp:
                    alpha = (t - event.t) / event.ramp
                    values[key] = values[key] + alpha * (target - values[key])
                else:
                    values[key] = target
        for wave in self.waves:
            values[wave.field] += wave.value(t)
        return Command.model_construct(set(values), **values)

    def command_field_at(self, field: str, times: NDArray[np.floating[Any]]) -> NDArray[np.float64]:
        """One field of :meth:`command_at` at each of ``times`` [s], in one call (the MPC reads
        its horizon's nodes every tick): the same arithmetic elementwise, so each value equals
        ``getattr(self.command_at(t), field)`` to the bit; a subclass that answers
        :meth:`command_at` otherwise is asked at each time.

        Raises:
            ConfigError: ``field`` is not a field of :class:`Command`.
        """
        if field not in _COMMAND_DEFAULTS:
            raise ConfigError(
                f"command field {field!r} is not one of {', '.join(_COMMAND_DEFAULTS)}"
            )
        times = np.asarray(times, dtype=np.float64)
        if type(self).command_at is not Scenario.command_at:  # a timeline of its own (a planner's)
            return np.array([getattr(self.command_at(t), field) for t in times.tolist()], float)
        values = np.full(times.shape, _COMMAND_DEFAULTS[field], dtype=np.float64)
        for event in self.commands:
            started = event.t <= times
            if not started.any():
                break  # in time order: no later event has started either
            target = event._fields.get(field)
            if target is None:
                continue
            if event.ramp > 0.0:
                ramping = started & (times < event.t + event.ramp)
                alpha = (times - event.t) / event.ramp
                ramped = values + alpha * (target - values)
                values = np.where(ramping, ramped, np.where(started, target, values))
            else:
                values = np.where(started, target, values)
        for wave in self.waves:
            if wave.field != field:
                continue
            inside = (wave.start <= times) & (times < wave.stop)
            # math.sin, as command_at's: NumPy's sin may differ from it in the last bit
            swing = [
                wave.amplitude * math.sin(2.0 * math.pi * (t - wave.start) / wave.period)
                for t in times[inside].tolist()
            ]
            added = np.zeros(times.shape)
            added[inside] = swing
            values = values + added
        return values

    def with_duration(self, duration: float) -> Scenario:
        return self.model_copy(update={"duration": duration})


def load_scenario_file(path: Path) -> Scenario:
    """Read and check a scenario file.

    Raises:
        ConfigError: Missing file, not TOML, or a bad field (named in the message).
    """
    return load_checked(path, Scenario, "scenario file")
