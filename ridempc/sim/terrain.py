"""The scenario's terrain as MuJoCo geoms, and the judge's height of the ground anywhere.

:func:`lay_out` turns the checked ``[[terrain]]`` items (:mod:`ridempc.scenarios.terrain`)
into a :class:`TerrainLayout` for the board ridden (heights in wheel radii resolved, the
board's limits checked); :func:`add_terrain` adds it to a scene's spec. Steps and slopes are
boxes: a heightfield would turn a step into a ramp one cell wide and, on flat ground, slow a
rolling wheel on its triangle edges. Only a rough patch is a heightfield.

The start (the origin) stays at :math:`z = 0`: a profile going down puts the floor plane
lower, so a ride on terrain starts exactly as one on flat ground. The controllers never see
any of this; only the fall detector and the metrics read :meth:`TerrainLayout.height_at`.
The terrain's geoms touch what the floor touches and a wheel's tread
(:mod:`ridempc.terrain_contact`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.errors import ConfigError
from ridempc.mjcf import STIFF_CONTACT
from ridempc.scenarios.terrain import (
    WORLD_FRONT,
    WORLD_HALF_WIDTH,
    Box,
    Rough,
    Slope,
    Stairs,
    Step,
    Strip,
    TerrainItem,
    footprint,
)
from ridempc.terrain_contact import TERRAIN_BITS

__all__ = [
    "STEP_DOWN_RADII",
    "STEP_UP_RADII",
    "TerrainBox",
    "TerrainField",
    "TerrainLayout",
    "add_terrain",
    "lay_out",
]

# A wheel rolls off an edge up to two radii high: lower than its own diameter, the shoe or
# deck meets the lower ground wheel first (the paper's Hovershoes went down 1.71 radii).
STEP_DOWN_RADII: float = 2.0
# A wheel climbs an edge while the contact force at the edge still points above its axle's
# height by enough to roll it up: half a radius (the edge at 60 deg from the vertical).
STEP_UP_RADII: float = 0.5
# The ground behind the start [m]: a rider backing off stays on the world.
WORLD_BACK: float = WORLD_HALF_WIDTH
# Cells per noise wavelength of a rough patch's heightfield: a wave drawn smoothly.
CELLS_PER_WAVELENGTH: int = 6
# The largest heightfield side [cells]: 400 x 400 floats compile and collide quickly.
MAX_CELLS: int = 400
# Plane waves summed in a rough patch's noise: enough for no visible pattern.
NOISE_WAVES: int = 24
# Each wave's length is the patch's wavelength times a factor drawn in this range.
NOISE_SPREAD: tuple[float, float] = (0.7, 1.4)
# Depth of a box's or heightfield's base below the floor [m], so no edge shows at the floor.
BURY: float = 0.05
TERRAIN_RGBA: tuple[float, float, float, float] = (0.55, 0.5, 0.42, 1.0)


@dataclass(frozen=True)
class TerrainBox:
    """A box of the terrain.

    Attributes:
        center: Its centre in the world [m].
        half: Its half extents in its own axes [m].
        pitch: Its inclination about world y [rad], positive rising along +x.
    """

    center: tuple[float, float, float]
    half: tuple[float, float, float]
    pitch: float = 0.0


@dataclass(frozen=True)
class TerrainField:
    """A rough patch: heights over a regular grid, about the level under it.

    Attributes:
        x: Grid coordinates along x [m], shape (ncol,).
        y: Grid coordinates along y [m], shape (nrow,).
        heights: Height over the level [m], shape (nrow, ncol), row i at ``y[i]``.
        level: The level under the patch [m].
    """

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    heights: NDArray[np.float64]
    level: float

    def height_at(self, x: float, y: float) -> float:
        """Bilinear height of the grid at (x, y) [m] (MuJoCo's triangles differ by less
        than a cell's curvature)."""
        i = float(np.interp(y, self.y, np.arange(len(self.y))))
        j = float(np.interp(x, self.x, np.arange(len(self.x))))
        i0, j0 = min(int(i), len(self.y) - 2), min(int(j), len(self.x) - 2)
        a, b = i - i0, j - j0
        h = self.heights
        top = (1 - b) * h[i0, j0] + b * h[i0, j0 + 1]
        bottom = (1 - b) * h[i0 + 1, j0] + b * h[i0 + 1, j0 + 1]
        return self.level + float((1 - a) * top + a * bottom)


@dataclass(frozen=True)
class _Segment:
    """A piece of the profile: the ground from ``x0`` to ``x1`` goes from ``z0`` to ``z1``."""

    x0: float
    x1: float
    z0: float
    z1: float

    def height(self, x: float) -> float:
        if self.x1 == self.x0:
            return self.z0
        return self.z0 + (self.z1 - self.z0) * (x - self.x0) / (self.x1 - self.x0)


@dataclass(frozen=True)
class TerrainLayout:
    """The terrain of one ride, resolved for its board.

    Attributes:
        floor_z: Height of the floor plane [m] (the lowest ground, at most 0).
        boxes: The terrain's boxes.
        fields: Its rough patches.
        edges: Each step's edge, ``(x [m], rise [m])`` (negative rise: a step down).
        segments: The profile along x, from behind the start to the world's front.
        items: The resolved items (heights in metres), in the file's order.
    """

    floor_z: float
    boxes: tuple[TerrainBox, ...]
    fields: tuple[TerrainField, ...]
    edges: tuple[tuple[float, float], ...]
    segments: tuple[_Segment, ...]
    items: tuple[TerrainItem, ...] = field(default=())

    def level_at(self, x: float) -> float:
        """The profile's height at ``x`` [m] (slopes, steps, stairs only)."""
        for seg in self.segments:
            if x < seg.x1:
                return seg.height(max(x, seg.x0))
        return self.segments[-1].z1

    def height_at(self, x: float, y: float) -> float:
        """Height of the ground at (x, y) [m]: the judge's view, never a controller's."""
        level = self.level_at(x)
        for patch in self.fields:
            if patch.x[0] <= x <= patch.x[-1] and patch.y[0] <= y <= patch.y[-1]:
                return patch.height_at(x, y)
        for item in self.items:
            x0, x1, y0, y1 = footprint(item)
            if not (x0 <= x <= x1 and y0 <= y <= y1):
                continue
            if isinstance(item, Strip):
                rise = float(item.height or 0.0)
                if item.ramp > 0.0:
                    into = min(x - x0, x1 - x)
                    rise *= min(1.0, into / item.ramp)
                return level + rise
            if isinstance(item, Box):
                return level + item.size[2]
        return level


def _heights(
    values: tuple[float, ...] | None, radii: tuple[float, ...] | None, r: float
) -> tuple[float, ...]:
    """Heights in metres, from metres or wheel radii."""
    return tuple(values) if values is not None else tuple(h * r for h in radii or ())


def _resolved(item: TerrainItem, index: int, wheel_radius: float | None, board: str) -> TerrainItem:
    """The item with its heights in metres, checked against what the board can roll."""
    if wheel_radius is None:  # no board: nothing to roll, heights in metres only
        for name in ("height_radii", "heights_radii"):
            if getattr(item, name, None) is not None:
                raise ConfigError(
                    f"field 'terrain.{index}.{name}': board '{board}' has no wheels; "
                    "allowed: a height in metres"
                )
        return item
    if isinstance(item, Step | Stairs | Strip):
        if isinstance(item, Stairs):
            metres = _heights(item.heights, item.heights_radii, wheel_radius)
            given = "heights" if item.heights is not None else "heights_radii"
            direction = item.direction
        else:
            metres = _heights(
                None if item.height is None else (item.height,),
                None if item.height_radii is None else (item.height_radii,),
                wheel_radius,
            )
            given = "height" if item.height is not None else "height_radii"
            direction = item.direction if isinstance(item, Step) else "up"
        if isinstance(item, Strip) and item.ramp > 0.0:
            limit = math.inf  # a ramped strip is rolled up, not climbed
        else:
            limit = (STEP_DOWN_RADII if direction == "down" else STEP_UP_RADII) * wheel_radius
        for k, h in enumerate(metres):
            if h > limit:
                where = f"{given}.{k}" if isinstance(item, Stairs) else given
                raise ConfigError(
                    f"field 'terrain.{index}.{where}': a step {direction} of {h:.4g} m is "
                    f"higher than board '{board}' can roll {direction} (allowed: up to "
                    f"{limit:.4g} m, {limit / wheel_radius:g} wheel radii of "
                    f"{wheel_radius:g} m)"
                )
        if isinstance(item, Stairs):
            return item.model_copy(update={"heights": metres, "heights_radii": None})
        return item.model_copy(update={"height": metres[0], "height_radii": None})
    return item


def _profile(items: tuple[TerrainItem, ...]) -> tuple[list[_Segment], list[tuple[float, float]]]:
    """The ground along x (flat and inclined pieces) and the steps' edges."""
    changes: list[tuple[float, float, float]] = []  # (x0, x1, rise)
    for item in items:
        sign = 1.0
        if isinstance(item, Slope | Step | Stairs):
            sign = 1.0 if item.direction == "up" else -1.0
        if isinstance(item, Slope):
            rise = sign * item.length * math.tan(math.radians(item.angle))
            changes.append((item.start, item.start + item.length, rise))
        elif isinstance(item, Step):
            changes.append((item.at, item.at, sign * float(item.height or 0.0)))
        elif isinstance(item, Stairs):
            for k, h in enumerate(item.heights or ()):
                edge = item.at + k * item.tread
                changes.append((edge, edge, sign * h))
    segments: list[_Segment] = []
    edges: list[tuple[float, float]] = []
    x, level = -WORLD_BACK, 0.0
    for x0, x1, rise in sorted(changes):
        if x0 > x:
            segments.append(_Segment(x, x0, level, level))
        if x1 > x0:
            segments.append(_Segment(x0, x1, level, level + rise))
        else:
            edges.append((x0, rise))
        x, level = x1, level + rise
    segments.append(_Segment(x, WORLD_FRONT + WORLD_BACK, level, level))
    return segments, edges


def _noise(item: Rough) -> TerrainField:
    r"""Smooth noise of peak ``amplitude``: a sum of plane waves
    :math:`\sum_k \cos(\mathbf{k}_k \cdot \mathbf{p} + \phi_k)` with wavelengths about the
    patch's, tapered to zero over a wavelength at each edge so the patch meets the level."""
    x0, x1, y0, y1 = footprint(item)
    cell = item.wavelength / CELLS_PER_WAVELENGTH
    ncol = int(min(MAX_CELLS, max(3, math.ceil((x1 - x0) / cell) + 1)))
    nrow = int(min(MAX_CELLS, max(3, math.ceil((y1 - y0) / cell) + 1)))
    xs, ys = np.linspace(x0, x1, ncol), np.linspace(y0, y1, nrow)
    gx, gy = np.meshgrid(xs, ys)
    rng = np.random.default_rng(item.seed)
    heights = np.zeros_like(gx)
    for _ in range(NOISE_WAVES):
        k = 2.0 * math.pi / (item.wavelength * rng.uniform(*NOISE_SPREAD))
        angle, phase = rng.uniform(0.0, 2.0 * math.pi, size=2)
        heights += np.cos(k * (math.cos(angle) * gx + math.sin(angle) * gy) + phase)

    def taper(d: NDArray[np.float64]) -> NDArray[np.float64]:
        s = np.clip(d / item.wavelength, 0.0, 1.0)
        return s * s * (3.0 - 2.0 * s)  # smoothstep

    heights *= taper(np.minimum(gx - x0, x1 - gx)) * taper(np.minimum(gy - y0, y1 - gy))
    peak = float(np.abs(heights).max())
    heights *= item.amplitude / peak if peak > 0.0 else 0.0
    return TerrainField(x=xs, y=ys, heights=heights, level=0.0)


def wheel_radius_of(board: Board | None) -> float | None:
    """The wheel radius of ``board`` [m], in which a step's height may be given; None
    without a board, or on a board without wheels."""
    return getattr(board.params, "wheel_radius", None) if board is not None else None


def lay_out_under(
    items: tuple[TerrainItem, ...], board: Board | None, board_name: str
) -> TerrainLayout | None:
    """:func:`lay_out` of ``items`` for ``board`` (named ``board_name``), None without items.

    Raises:
        ConfigError: As :func:`lay_out`.
    """
    return lay_out(items, wheel_radius_of(board), board_name) if items else None


def lay_out(
    items: tuple[TerrainItem, ...], wheel_radius: float | None, board: str = "none"
) -> TerrainLayout:
    """The terrain for a board of wheel radius ``wheel_radius`` [m] (None: no board).

    Raises:
        ConfigError: A step (or stair) higher than the board can roll, the field named.
    """
    resolved = tuple(_resolved(item, i, wheel_radius, board) for i, item in enumerate(items))
    segments, edges = _profile(resolved)
    level_of = TerrainLayout(0.0, (), (), (), tuple(segments)).level_at
    fields = []
    for item in resolved:
        if isinstance(item, Rough):
            patch = _noise(item)
            x0 = footprint(item)[0]
            fields.append(TerrainField(patch.x, patch.y, patch.heights, level=level_of(x0)))
    lows = [min(s.z0, s.z1) for s in segments] + [f.level + float(f.heights.min()) for f in fields]
    floor_z = min(0.0, *lows)
    holes = [
        (footprint(item), f)
        for item, f in zip([i for i in resolved if isinstance(i, Rough)], fields, strict=True)
    ]
    boxes: list[TerrainBox] = []
    for seg in segments:
        if seg.z0 == seg.z1:
            boxes += _slab(seg, floor_z, holes)
        else:
            boxes.append(
                _ramp(
                    seg.x0, seg.x1, seg.z0, seg.z1, (-WORLD_HALF_WIDTH, WORLD_HALF_WIDTH), floor_z
                )
            )
    for item in resolved:
        x0, x1, y0, y1 = footprint(item)
        level = level_of(x0)
        if isinstance(item, Strip):
            top = level + float(item.height or 0.0)
            a, b = x0 + item.ramp, x1 - item.ramp
            boxes.append(_block(a, b, y0, y1, level - BURY, top))
            if item.ramp > 0.0:
                boxes.append(_ramp(x0, a, level, top, (y0, y1), level - BURY))
                boxes.append(_ramp(b, x1, top, level, (y0, y1), level - BURY))
        elif isinstance(item, Box):
            boxes.append(_block(x0, x1, y0, y1, level, level + item.size[2]))
    return TerrainLayout(
        floor_z=floor_z,
        boxes=tuple(boxes),
        fields=tuple(fields),
        edges=tuple(edges),
        segments=tuple(segments),
        items=resolved,
    )


def _block(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> TerrainBox:
    return TerrainBox(
        center=((x0 + x1) / 2.0, (y0 + y1) / 2.0, (z0 + z1) / 2.0),
        half=((x1 - x0) / 2.0, (y1 - y0) / 2.0, (z1 - z0) / 2.0),
    )


def _slab(
    seg: _Segment,
    floor_z: float,
    holes: list[tuple[tuple[float, float, float, float], TerrainField]],
) -> list[TerrainBox]:
    """A flat piece of the profile as boxes, lowered under each rough patch to its lowest
    point (the patch's cracks go below the level)."""
    level = seg.z0
    inside = [(p, f) for p, f in holes if seg.x0 <= p[0] and p[1] <= seg.x1]
    xs = sorted({seg.x0, seg.x1, *(v for p, _ in inside for v in p[:2])})
    boxes = []
    for a, b in zip(xs[:-1], xs[1:], strict=True):
        here = [(p, f) for p, f in inside if p[0] <= a and b <= p[1]]
        ys = sorted({-WORLD_HALF_WIDTH, WORLD_HALF_WIDTH, *(v for p, _ in here for v in p[2:])})
        for c, d in zip(ys[:-1], ys[1:], strict=True):
            top = level
            for p, f in here:
                if p[2] <= c and d <= p[3]:
                    top = level + float(f.heights.min())
            if top > floor_z and b > a:
                boxes.append(_block(a, b, c, d, floor_z - BURY, top))
    return boxes


def _ramp(
    x0: float, x1: float, z0: float, z1: float, y: tuple[float, float], floor_z: float
) -> TerrainBox:
    """A box whose top face runs from (x0, z0) to (x1, z1), deep enough to reach the floor."""
    pitch = math.atan2(z1 - z0, x1 - x0)
    half_length = math.hypot(x1 - x0, z1 - z0) / 2.0
    half_depth = (max(z0, z1) - floor_z + BURY) / math.cos(pitch) / 2.0
    normal = (-math.sin(pitch), math.cos(pitch))  # of the top face, in (x, z)
    mid = ((x0 + x1) / 2.0, (z0 + z1) / 2.0)
    return TerrainBox(
        center=(
            mid[0] - half_depth * normal[0],
            (y[0] + y[1]) / 2.0,
            mid[1] - half_depth * normal[1],
        ),
        half=(half_length, (y[1] - y[0]) / 2.0, half_depth),
        pitch=pitch,
    )


def add_terrain(spec: mujoco.MjSpec, layout: TerrainLayout, floor: str = "floor") -> list[str]:
    """Add the terrain to a scene's spec (the floor plane moved to ``floor_z``); returns the
    names of the terrain's geoms, which touch what the floor touches."""
    spec.geom(floor).pos = [0.0, 0.0, layout.floor_z]
    contact = {**TERRAIN_BITS, "condim": 3, **STIFF_CONTACT}
    template = spec.geom(floor)
    names = []
    for i, box in enumerate(layout.boxes):
        name = f"terrain/box{i}"
        # a rotation about +y by -pitch tilts the box's +x axis up by pitch
        quat = [math.cos(-box.pitch / 2.0), 0.0, math.sin(-box.pitch / 2.0), 0.0]
        spec.worldbody.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            pos=list(box.center),
            quat=quat,
            size=list(box.half),
            friction=list(template.friction),
            rgba=list(TERRAIN_RGBA),
            **contact,
        )
        names.append(name)
    for i, patch in enumerate(layout.fields):
        low, high = float(patch.heights.min()), float(patch.heights.max())
        span = max(high - low, 1e-6)
        data = ((patch.heights - low) / span).ravel()
        spec.add_hfield(
            name=f"terrain/rough{i}",
            size=[
                (patch.x[-1] - patch.x[0]) / 2.0,
                (patch.y[-1] - patch.y[0]) / 2.0,
                span,
                patch.level + low - layout.floor_z + BURY,
            ],
            nrow=len(patch.y),
            ncol=len(patch.x),
            userdata=data.tolist(),
        )
        name = f"terrain/rough{i}"
        spec.worldbody.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_HFIELD,
            hfieldname=f"terrain/rough{i}",
            pos=[
                (patch.x[-1] + patch.x[0]) / 2.0,
                (patch.y[-1] + patch.y[0]) / 2.0,
                patch.level + low,
            ],
            friction=list(template.friction),
            rgba=list(TERRAIN_RGBA),
            **contact,
        )
        names.append(name)
    return names
