"""Terrain items of a scenario: the ``[[terrain]]`` tables (Hovershoes paper, Fig. 9-10).

The rider starts at the origin on level ground and rides along world :math:`+x`. Slopes,
steps and stairs change the ground's level for everything beyond them (the *profile*, built
of boxes across the whole world's width); a rough patch, a raised strip and a box sit on the
level where they are. Example::

    [[terrain]]
    kind = "slope"
    start = 2.0                # [m] along x, where the incline begins
    length = 3.0               # [m] horizontal run; level again after it
    angle = 7.0                # [deg]
    direction = "up"

    [[terrain]]
    kind = "step"
    at = 6.0                   # [m] along x, the edge
    height_radii = 1.71        # or height = 0.076 [m]; exactly one of them
    direction = "down"

    [[terrain]]
    kind = "stairs"
    at = 8.0                   # [m] the first edge
    heights_radii = [0.79, 0.93, 0.93]   # or heights [m]
    tread = 0.6                # [m] from one edge to the next
    direction = "down"

    [[terrain]]
    kind = "rough"
    start = 2.0                # [m]
    length = 4.0               # [m]
    y = [-1.0, 1.0]            # [m] lateral extent
    amplitude = 0.01           # [m] the highest bump and the deepest crack
    wavelength = 0.3           # [m] of the smooth noise
    seed = 0

    [[terrain]]
    kind = "strip"             # a raised strip under one shoe, with ramps at both ends
    start = 2.0
    length = 3.0
    y = [0.05, 0.5]            # [m]
    height = 0.03              # [m] (or height_radii)
    ramp = 0.3                 # [m] horizontal length of each end's ramp; 0: a sharp edge

    [[terrain]]
    kind = "box"
    center = [4.0, 1.0]        # [m] (x, y)
    size = [0.2, 0.2, 0.1]     # [m] full extents; its bottom on the level under it

Heights given in wheel radii are resolved, and the board's limits checked, when the scene
is built (:mod:`ridempc.sim.terrain`), since they depend on the board ridden.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from ridempc.units import CheckedModel, Count, Real

__all__ = [
    "Box",
    "Rough",
    "START_CLEARANCE",
    "Slope",
    "Stairs",
    "Step",
    "Strip",
    "TerrainItem",
    "WORLD_FRONT",
    "WORLD_HALF_WIDTH",
    "check_terrain",
    "footprint",
    "step_edges",
]

# The world: a 100 m run ahead of the start (200 s at 0.5 m/s, beyond any scenario) and 10 m
# to each side (the widest turn of the library's circles); terrain beyond it is a typo.
WORLD_FRONT: float = 100.0  # [m]
WORLD_HALF_WIDTH: float = 10.0  # [m]
# No terrain within this distance of the start along x: every board (the skateboard's deck is
# 0.74 m long) starts on level ground at the origin.
START_CLEARANCE: float = 0.5  # [m]

Along = Annotated[Real, Field(ge=START_CLEARANCE, le=WORLD_FRONT, description="[m]")]
Span = Annotated[Real, Field(gt=0.0, le=WORLD_FRONT, description="[m]")]
Lateral = Annotated[Real, Field(ge=-WORLD_HALF_WIDTH, le=WORLD_HALF_WIDTH, description="[m]")]
# One metre is a wall to every board here (the Segway's wheel radius is 0.13 m).
Height = Annotated[Real, Field(gt=0.0, le=1.0, description="[m]")]
# Ten wheel radii: beyond any step a wheel rolls over (the paper's highest: 1.71).
Radii = Annotated[Real, Field(gt=0.0, le=10.0, description="[wheel radii]")]
# 30 deg: steeper than any ramp a wheeled board is ridden on (the paper's steepest: 13 deg).
SlopeAngle = Annotated[Real, Field(gt=0.0, le=30.0, description="[deg]")]
Direction = Literal["up", "down"]


class _Item(CheckedModel):
    """A terrain item: strict numbers, no NaN, no unknown keys, immutable."""


def _one_height(
    metres: object, radii: object, names: tuple[str, str] = ("height", "height_radii")
) -> None:
    if (metres is None) == (radii is None):
        raise ValueError(f"takes exactly one of {names[0]} [m] or {names[1]} [wheel radii]")


class Slope(_Item):
    """An incline from ``start`` over ``length`` (horizontal), level again after it.

    Attributes:
        start: Where the incline begins, along x [m].
        length: Its horizontal run [m].
        angle: Its inclination [deg].
        direction: ``up`` or ``down`` along +x.
    """

    kind: Literal["slope"]
    start: Along
    length: Span
    angle: SlopeAngle
    direction: Direction


class Step(_Item):
    """A vertical edge at ``at`` where the ground rises or drops by the height."""

    kind: Literal["step"]
    at: Along
    height: Height | None = None  # [m]
    height_radii: Radii | None = None  # [wheel radii of the board ridden]
    direction: Direction

    @model_validator(mode="after")
    def _height(self) -> Step:
        _one_height(self.height, self.height_radii)
        return self


class Stairs(_Item):
    """Steps one ``tread`` apart, the first edge at ``at``."""

    kind: Literal["stairs"]
    at: Along
    heights: tuple[Height, ...] | None = None  # [m]
    heights_radii: tuple[Radii, ...] | None = None  # [wheel radii]
    tread: Span  # [m] from one edge to the next
    direction: Direction

    @model_validator(mode="after")
    def _heights(self) -> Stairs:
        _one_height(self.heights, self.heights_radii, ("heights", "heights_radii"))
        count = len(self.heights or self.heights_radii or ())
        if not 1 <= count <= 20:  # a longer flight is a typo in this world
            raise ValueError(f"stairs take 1 to 20 heights, got {count}")
        return self

    @property
    def count(self) -> int:
        return len(self.heights or self.heights_radii or ())


class Rough(_Item):
    """A patch of smooth noise (a heightfield): bumps and cracks up to ``amplitude``."""

    kind: Literal["rough"]
    start: Along
    length: Span
    y: tuple[Lateral, Lateral] = (-1.0, 1.0)  # [m] lateral extent, low to high
    # 5 cm: half a Hovershoe deck's height over the ground; more is an obstacle, not roughness.
    amplitude: Annotated[Real, Field(gt=0.0, le=0.05, description="[m]")]
    # from 5 cm (a crack) to 2 m (a gentle undulation)
    wavelength: Annotated[Real, Field(ge=0.05, le=2.0, description="[m]")]
    seed: Annotated[Count, Field(ge=0, le=2**31 - 1)] = 0


class Strip(_Item):
    """A raised strip (the shoes at different heights): a plateau with a ramp at each end."""

    kind: Literal["strip"]
    start: Along
    length: Span
    y: tuple[Lateral, Lateral]  # [m] lateral extent, low to high
    height: Height | None = None  # [m]
    height_radii: Radii | None = None  # [wheel radii]
    ramp: Annotated[Real, Field(ge=0.0, le=5.0, description="[m]")] = 0.0

    @model_validator(mode="after")
    def _shape(self) -> Strip:
        _one_height(self.height, self.height_radii)
        if 2.0 * self.ramp >= self.length:
            raise ValueError(f"ramp = {self.ramp} m leaves no plateau on length {self.length} m")
        return self


class Box(_Item):
    """A box standing on the level under it (an obstacle, a kerb stone)."""

    kind: Literal["box"]
    center: tuple[Along, Lateral]  # [m] (x, y)
    size: tuple[Span, Span, Height]  # [m] full extents (x, y, z)


TerrainItem = Annotated[Slope | Step | Stairs | Rough | Strip | Box, Field(discriminator="kind")]


def footprint(item: TerrainItem) -> tuple[float, float, float, float]:
    """The ground an item takes, ``(x0, x1, y0, y1)`` [m]; a profile item spans the world's
    width (a step's edge: ``x0 == x1``)."""
    wide = (-WORLD_HALF_WIDTH, WORLD_HALF_WIDTH)
    if isinstance(item, Slope):
        return (item.start, item.start + item.length, *wide)
    if isinstance(item, Step):
        return (item.at, item.at, *wide)
    if isinstance(item, Stairs):
        return (item.at, item.at + (item.count - 1) * item.tread, *wide)
    if isinstance(item, Rough | Strip):
        return (item.start, item.start + item.length, *item.y)
    half = (item.size[0] / 2.0, item.size[1] / 2.0)
    return (
        item.center[0] - half[0],
        item.center[0] + half[0],
        item.center[1] - half[1],
        item.center[1] + half[1],
    )


def step_edges(items: tuple[TerrainItem, ...]) -> tuple[float, ...]:
    """Where each step's edge lies along x [m], stairs one per step, in order along x."""
    edges = [item.at for item in items if isinstance(item, Step)]
    for item in items:
        if isinstance(item, Stairs):
            edges += [item.at + k * item.tread for k in range(item.count)]
    return tuple(sorted(edges))


def _overlap(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    """Whether two footprints share ground (touching edges do not)."""
    return (
        a[0] < b[1]
        and b[0] < a[1]
        and a[2] < b[3]
        and b[2] < a[3]
        or (
            a[0] == a[1] == b[0] == b[1]  # two edges at the same place
        )
    )


def check_terrain(items: tuple[TerrainItem, ...]) -> None:
    """Refuse terrain outside the world and items sharing ground, naming the first one.

    A profile item (slope, step, stairs) may touch its neighbour (a slope ending at a step);
    a rough patch, a strip or a box needs one level under it, so nothing may reach into it.

    Raises:
        ValueError: ``terrain.<i>``: what is wrong (pydantic turns it into a ConfigError).
    """
    prints = [footprint(item) for item in items]
    for i, (item, (x0, x1, y0, y1)) in enumerate(zip(items, prints, strict=True)):
        if x1 > WORLD_FRONT:
            raise ValueError(
                f"terrain.{i}: {item.kind} ends at x = {x1:g} m, outside the world "
                f"(x in [{START_CLEARANCE:g}, {WORLD_FRONT:g}] m)"
            )
        if y0 >= y1:
            raise ValueError(f"terrain.{i}: y = [{y0:g}, {y1:g}] m must run from low to high")
        if x0 < START_CLEARANCE:
            raise ValueError(
                f"terrain.{i}: {item.kind} starts at x = {x0:g} m, under the start "
                f"(allowed: x >= {START_CLEARANCE:g} m)"
            )
        for j in range(i):
            if _overlap(prints[j], prints[i]):
                raise ValueError(
                    f"terrain.{i}: {item.kind} overlaps terrain.{j} ({items[j].kind}) "
                    f"in x [{x0:g}, {x1:g}] m, y [{y0:g}, {y1:g}] m"
                )
