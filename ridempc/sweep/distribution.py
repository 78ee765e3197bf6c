"""Distributions: which quantities a sweep draws for each variant of a scenario, and how.

A distribution is a checked TOML file, shipped in ``ridempc/scenarios/distributions/``
(``<board>/<name>.toml`` for one board, ``<name>.toml`` for any) or given by path. Each
quantity is a number (fixed) or a law: ``{uniform = [low, high]}``, ``{normal = [mean, std],
clip = [low, high]}`` (clipped to a physical range) or ``{choice = [a, b, ...]}`` (one of them,
equally likely). Example::

    name = "everyday"
    board = "hovershoes"                     # omitted: any board

    [[pushes]]                               # a horizontal push on the rider's base
    magnitude = {uniform = [0.0, 1.0]}       # [N/kg] of the rider's mass
    direction = {uniform = [0.0, 360.0]}     # [deg] world frame, 0 = +x (ahead at the start)
    t = {uniform = [2.0, 8.0]}               # [s]
    duration = {uniform = [0.1, 0.3]}        # [s]

    [[kicks]]                                # a horizontal push on a board body
    body = "left_shoe"
    magnitude = {uniform = [0.0, 25.0]}      # [N]
    direction = {uniform = [0.0, 360.0]}     # [deg]
    t = {uniform = [2.0, 8.0]}               # [s]
    duration = 0.1                           # [s]

    [terrain]                                # a slope or a step ahead (ridempc.sweep.terrain_draws)
    probability = 0.8
    kinds = ["slope", "step"]
    start = {uniform = [1.0, 2.0]}           # [m] along x
    slope_deg = {uniform = [-5.0, 5.0]}      # [deg] positive up
    step_height_radii = {uniform = [-0.6, -0.1]}   # [wheel radii] positive up

    [steering]                               # a turn (ridempc.sweep.steering_draws)
    yaw_rate = {uniform = [-0.3, 0.3]}       # [rad/s] positive to the left
    t = {uniform = [3.0, 6.0]}               # [s]
    duration = {uniform = [1.0, 3.0]}        # [s]

    [payload]                                # a point mass on a rider body
    body = "base"
    fraction = {uniform = [0.0, 0.1]}        # of the rider's mass [-]
    offset = [0.0, 0.0, {uniform = [0.0, 0.1]}]   # body frame [m]

    [start]                                  # added to the scenario's start offsets [m]
    foot_offset = [{uniform = [-0.01, 0.01]}, {uniform = [-0.01, 0.01]}]
    platform_offsets = [{uniform = [-0.015, 0.015]}, 0.0]   # each independent platform

    [noise]                                  # the scenario's sensor noise scaled [-]
    scale = {uniform = [1.0, 1.5]}           # every noise standard deviation
    vio_latency_scale = {uniform = [1.0, 1.5]}

    [[changes]]                              # a knob of a scenario's [[changes]]
    parameter = "floor_friction"
    value = {uniform = [0.6, 1.0]}           # or scale = ...; body, gain, joint as there
    body = ["left_shoe", "right_shoe"]       # (board_mass, payload-free knobs) one draw each

Every number is checked finite and within physical bounds, every range non-empty; a
``[[changes]]`` entry is checked by the knob's own rules at both ends of its range. Each
drawn quantity has a dotted name (:meth:`Distribution.quantities`), e.g.
``push.magnitude``, ``kick.direction``, ``payload.offset.z``,
``start.platform_offsets.1.x``, ``noise.scale``, ``changes.board_mass.left_shoe.scale``,
``terrain.slope_deg``, ``steering.yaw_rate``;
an index follows ``push`` and ``kick`` where there are several (``push.0.t``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import (
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.scenarios.scenario import ParameterChange
from ridempc.sim.knobs import KNOBS, PAYLOAD_OFFSET_MAX
from ridempc.sim.terrain import wheel_radius_of
from ridempc.sweep.laws import Law, Quantity, within
from ridempc.sweep.steering_draws import SteeringDraws
from ridempc.sweep.terrain_draws import TerrainDraws
from ridempc.tomlfile import load_checked
from ridempc.units import MAX_DURATION, CheckedModel

__all__ = [
    "DISTRIBUTIONS_DIR",
    "Distribution",
    "DrawnChange",
    "Kick",
    "Law",
    "NoiseScales",
    "Payload",
    "Push",
    "StartOffsets",
    "distribution_boards",
    "distribution_files",
    "distribution_names",
    "load_distribution",
]

DISTRIBUTIONS_DIR = Path(__file__).resolve().parents[1] / "scenarios" / "distributions"

# A push of 100 N/kg (ten g) throws any of the robots: the scenario's bound on a push.
PushMagnitude = Annotated[Quantity, within(0.0, 100.0, "N/kg")]
# A kick of 10 kN throws any board: the scenario's bound on a force.
KickMagnitude = Annotated[Quantity, within(0.0, 10_000.0, "N")]
Direction = Annotated[Quantity, within(-360.0, 360.0, "deg")]
EventTime = Annotated[Quantity, within(0.0, MAX_DURATION, "s")]
# A push longer than 5 s is a load, not a push: the scenario's bound.
PushDuration = Annotated[Quantity, within(0.0, 5.0, "s", low_open=True)]
# At most the rider's own mass again: more is a second rider, not a payload; at least half of
# it taken off (negative: a lighter rider, the knob's links scaled): less is another robot.
MassFraction = Annotated[Quantity, within(-0.5, 1.0, "")]
PayloadOffset = Annotated[Quantity, within(-PAYLOAD_OFFSET_MAX, PAYLOAD_OFFSET_MAX, "m")]
# A foot or platform moved by more than half a metre is off any deck: the scenario's bound.
StartOffset = Annotated[Quantity, within(-0.5, 0.5, "m")]
# Ten times a sensor's noise or delay is a broken sensor, not a robustness study.
NoiseScale = Annotated[Quantity, within(0.0, 10.0, "", low_open=True)]


class _Frozen(CheckedModel):
    """Strict numbers, no NaN, no unknown keys, immutable."""


class _Event(_Frozen):
    """A horizontal force for a while.

    Attributes:
        direction: In the horizontal plane of the world frame, counter-clockwise from +x
            (the rider's heading at the start) [deg].
        t: When it starts [s].
    """

    direction: Direction = Law(fixed=0.0)
    t: EventTime

    def quantities(self, prefix: str) -> dict[str, Law]:
        names = ("magnitude", "direction", "t", "duration")
        return {f"{prefix}.{name}": getattr(self, name) for name in names}


class Push(_Event):
    """A horizontal push on the rider's base, per kg of its mass.

    Attributes:
        magnitude: [N/kg].
        duration: How long it lasts [s] (the library's pushes: 0.2 s).
    """

    magnitude: PushMagnitude
    duration: PushDuration = Law(fixed=0.2)


class Kick(_Event):
    """A horizontal push on a board body.

    Attributes:
        body: The board body (e.g. ``left_shoe``, ``chassis``, ``deck``).
        magnitude: [N].
        duration: How long it lasts [s] (the library's kicks: 0.1 s).
    """

    body: str = Field(min_length=1)
    magnitude: KickMagnitude
    duration: PushDuration = Law(fixed=0.1)


class Payload(_Frozen):
    """A point mass on a rider body (a ``payload`` change); none where its mass draws 0.

    Attributes:
        body: ``base`` or a body of the robot.
        fraction: Its mass over the rider's [-] (negative: a lighter rider, ``payload``'s
            knob, :mod:`ridempc.sim.knobs`).
        offset: Its position in the body's frame [m].
    """

    body: str = "base"
    fraction: MassFraction
    offset: tuple[PayloadOffset, PayloadOffset, PayloadOffset] = (
        Law(fixed=0.0),
        Law(fixed=0.0),
        Law(fixed=0.0),
    )

    def quantities(self) -> dict[str, Law]:
        axes = {f"payload.offset.{a}": law for a, law in zip("xyz", self.offset, strict=True)}
        return {"payload.fraction": self.fraction, **axes}


class StartOffsets(_Frozen):
    """Start offsets added to the scenario's own.

    Attributes:
        foot_offset: The feet off the platform centre, (x, y) [m].
        platform_offsets: Each independent platform moved, (x, y) [m], drawn for each one
            (boards with several platforms only: the Hovershoes).
    """

    foot_offset: tuple[StartOffset, StartOffset] = (Law(fixed=0.0), Law(fixed=0.0))
    platform_offsets: tuple[StartOffset, StartOffset] | None = None

    def quantities(self, platforms: int) -> dict[str, Law]:
        axes = zip("xy", self.foot_offset, strict=True)
        laws = {f"start.foot_offset.{axis}": law for axis, law in axes}
        if self.platform_offsets is not None:
            for i in range(platforms):
                for axis, law in zip("xy", self.platform_offsets, strict=True):
                    laws[f"start.platform_offsets.{i}.{axis}"] = law
        return laws


class NoiseScales(_Frozen):
    """The scenario's sensor noise scaled.

    Attributes:
        scale: Every noise standard deviation (IMU, encoder velocities, torques, VIO) [-].
        vio_latency_scale: The VIO's capture-to-delivery delay [-].
    """

    scale: NoiseScale = Law(fixed=1.0)
    vio_latency_scale: NoiseScale = Law(fixed=1.0)

    def quantities(self) -> dict[str, Law]:
        return {"noise.scale": self.scale, "noise.vio_latency_scale": self.vio_latency_scale}


class DrawnChange(_Frozen):
    """A knob of a scenario's ``[[changes]]`` (:data:`ridempc.sim.knobs.KNOBS`) set to a
    drawn ``value`` or ``scale``; ``body`` may list several bodies, each set to the same
    draw (both shoes of a pair). A payload is the ``[payload]`` table's.

    Attributes:
        t: When it takes effect [s] (0: before the first physics step).
        parameter: The knob.
        value: Its value [the knob's unit], or None.
        scale: Its value over the nominal one [-], or None.
        body: Where ``board_mass`` applies (one body or several).
        gain: Which firmware gain ``firmware_gain`` sets.
        joint: The joint ``joint_damping`` sets.
    """

    t: EventTime = Law(fixed=0.0)
    parameter: str
    value: Quantity | None = None
    scale: Quantity | None = None
    body: str | tuple[str, ...] | None = None
    gain: str | None = None
    joint: str | None = None

    @field_validator("parameter")
    @classmethod
    def _known(cls, name: str) -> str:
        if name == "payload":
            raise ValueError("a payload is drawn in the [payload] table")
        if name not in KNOBS:
            valid = ", ".join(sorted(k for k in KNOBS if k != "payload"))
            raise ValueError(f"unknown knob '{name}' (valid: {valid})")
        return name

    @model_validator(mode="after")
    def _knob_admits_both_ends(self) -> DrawnChange:
        """The knob's own rules (:class:`ParameterChange`) at the lowest and highest draw."""
        where = {"gain": self.gain, "joint": self.joint, "body": (*self.bodies, None)[0]}
        forms = {f: getattr(self, f) for f in ("value", "scale") if getattr(self, f) is not None}
        ends = [{f: law.bounds()[0] for f, law in forms.items()}]  # (none or both: refused)
        if len(forms) == 1:
            ends = [{f: end} for f, law in forms.items() for end in law.bounds()]
        for end in ends:
            try:
                ParameterChange.model_validate({"parameter": self.parameter, **where, **end})
            except ValidationError as exc:  # one line: the knob's own words
                raise ValueError(exc.errors()[0]["msg"].removeprefix("Value error, ")) from None
        return self

    @property
    def bodies(self) -> tuple[str, ...]:
        if self.body is None:
            return ()
        return (self.body,) if isinstance(self.body, str) else self.body

    @property
    def label(self) -> str:
        """Its dotted name without the form: ``changes.board_mass.left_shoe+right_shoe``."""
        where = "+".join(self.bodies) or self.gain or self.joint
        return f"changes.{self.parameter}" + (f".{where}" if where else "")

    def quantities(self) -> dict[str, Law]:
        laws = {f"{self.label}.{f}": getattr(self, f) for f in ("value", "scale")}
        laws = {name: law for name, law in laws.items() if law is not None}
        return {**laws, f"{self.label}.t": self.t}


class Distribution(_Frozen):
    """A checked, immutable distribution of scenario variants (module docstring).

    Attributes:
        name: Its name.
        description: One line: what it stands for.
        board: The board it is for, or None for any.
        pushes: Pushes on the rider's base.
        kicks: Kicks on board bodies.
        payload: A payload on the rider, or None.
        start: Start offsets, or None.
        noise: Sensor noise and VIO latency scales, or None.
        changes: Drawn knobs.
        terrain: A slope or a step ahead of the start
            (:class:`~ridempc.sweep.terrain_draws.TerrainDraws`), or None.
        steering: A turn at a drawn yaw rate
            (:class:`~ridempc.sweep.steering_draws.SteeringDraws`), or None.
    """

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9._-]*$")
    description: str = ""
    board: str | None = None
    pushes: tuple[Push, ...] = ()
    kicks: tuple[Kick, ...] = ()
    payload: Payload | None = None
    start: StartOffsets | None = None
    noise: NoiseScales | None = None
    changes: tuple[DrawnChange, ...] = ()
    terrain: TerrainDraws | None = None
    steering: SteeringDraws | None = None

    @model_validator(mode="after")
    def _one_draw_per_knob(self) -> Distribution:
        labels = [c.label for c in self.changes]
        twice = sorted({label for label in labels if labels.count(label) > 1})
        if twice:
            raise ValueError(f"{twice[0]} is drawn twice; allowed: one entry per knob and place")
        return self

    def quantities(self, platforms: int = 0) -> dict[str, Law]:
        """Every quantity by its dotted name, in drawing order.

        Args:
            platforms: The board's independent platforms (``start.platform_offsets`` are
                drawn for each).
        """
        laws: dict[str, Law] = {}
        for kind, events in (("push", self.pushes), ("kick", self.kicks)):
            for i, event in enumerate(events):
                laws |= event.quantities(kind if len(events) == 1 else f"{kind}.{i}")
        if self.payload is not None:
            laws |= self.payload.quantities()
        if self.start is not None:
            laws |= self.start.quantities(platforms)
        if self.noise is not None:
            laws |= self.noise.quantities()
        for change in self.changes:
            laws |= change.quantities()
        if self.terrain is not None:  # last: the other quantities draw as they did before it
            laws |= self.terrain.quantities()
        if self.steering is not None:
            laws |= self.steering.quantities()
        return laws


def distribution_names(board: str | None = None) -> tuple[str, ...]:
    """The shipped distributions for ``board`` (its own and those for any board), or every
    name when ``board`` is None."""
    patterns = ["**/*.toml"] if board is None else ["*.toml", f"{board}/*.toml"]
    return tuple(sorted({p.stem for pattern in patterns for p in DISTRIBUTIONS_DIR.glob(pattern)}))


def distribution_boards(name: str) -> tuple[str, ...]:
    """The boards the shipped distribution ``name`` is for (every board for one in the
    folder's top level)."""
    from ridempc.boards import board_names

    boards = [b for b in board_names() if b != "none"]
    if (DISTRIBUTIONS_DIR / f"{name}.toml").exists():
        return tuple(boards)
    return tuple(b for b in boards if (DISTRIBUTIONS_DIR / b / f"{name}.toml").exists())


def distribution_files() -> tuple[Path, ...]:
    """Every shipped distribution file."""
    return tuple(sorted(DISTRIBUTIONS_DIR.glob("**/*.toml")))


def load_distribution(name_or_path: str, board: str) -> Distribution:
    """A distribution for ``board``: a shipped name (the board's own where there is one) or
    a ``.toml`` path.

    Raises:
        UnknownNameError: Not a shipped name for ``board`` and not a ``.toml`` path.
        ConfigError: A file that is missing, unreadable or malformed, one for another board,
            or start offsets of platforms the board does not have (one line, naming the
            file, the field, the value and what is allowed).
    """
    from ridempc.boards import load_board

    loaded = load_board(board)  # UnknownNameError for an unknown board
    if name_or_path.lower().endswith(".toml") or "/" in name_or_path:
        path = Path(name_or_path)
    else:
        if name_or_path not in distribution_names(board):
            raise UnknownNameError("distribution", name_or_path, distribution_names(board))
        path = DISTRIBUTIONS_DIR / board / f"{name_or_path}.toml"
        if not path.exists():
            path = DISTRIBUTIONS_DIR / f"{name_or_path}.toml"
    distribution = load_checked(path, Distribution, "distribution file")
    if distribution.board is not None and distribution.board != board:
        raise ConfigError(
            f"{path}: field 'board': is '{distribution.board}'; allowed: '{board}' (the ride's "
            "board), or no board for a distribution that fits any"
        )
    terrain = distribution.terrain
    why = terrain.step_error(wheel_radius_of(loaded), board) if terrain is not None else None
    if why is not None:
        raise ConfigError(f"{path}: {why}")
    start = distribution.start
    platforms = len(loaded.params.platform_sites) if loaded is not None else 0
    if start is not None and start.platform_offsets is not None and platforms < 2:
        raise ConfigError(
            f"{path}: field 'start.platform_offsets': board '{board}' has no independent "
            "platforms; allowed: none (only the Hovershoes' platforms move apart)"
        )
    return distribution
