"""Obstacle courses: a checked TOML file of boxes, a start pose and a goal.

Example::

    name = "corridor"
    description = "A 7 m corridor with two boxes to weave around."
    duration = 40.0               # [s] the ride's time limit
    start = [0.0, 0.0, 0.0]       # x, y [m], heading [rad]
    goal = [7.0, 0.0]             # [m]
    goal_tolerance = 0.3          # [m]

    [[obstacles]]
    center = [2.5, 0.3]           # [m]
    size = [0.4, 0.4, 0.5]        # full lengths x, y and the height [m]
    yaw = 0.0                     # [rad]

    [[terrain]]                   # as in scenarios (ridempc.scenarios.terrain), in the
    kind = "slope"                # start's frame: x along the start heading
    start = 1.5
    length = 2.0
    angle = 7.0
    direction = "up"

A box stands on the ground's level under its centre. The scene is built with the rider at
its start pose; :meth:`Course.in_start_frame` gives the course in that frame (the rider's
starting base at the origin, heading along x).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from ridempc.errors import UnknownNameError
from ridempc.scenarios.terrain import TerrainItem, check_terrain
from ridempc.tomlfile import load_checked
from ridempc.units import CheckedModel, Real, RideDuration

__all__ = ["COURSE_DIR", "Box", "Course", "course_names", "load_course", "resolve_course"]

Array = NDArray[np.float64]

COURSE_DIR = Path(__file__).resolve().parent.parent / "scenarios" / "courses"
# A course spans a room: 50 m is beyond any the map's 5 cm grid holds in memory comfortably.
Coordinate = Annotated[Real, Field(ge=-50.0, le=50.0, description="[m]")]
Length = Annotated[Real, Field(gt=0.0, le=20.0, description="[m]")]
Height = Annotated[Real, Field(gt=0.0, le=3.0, description="[m]")]
Angle = Annotated[Real, Field(ge=-2.0 * math.pi, le=2.0 * math.pi, description="[rad]")]


class Box(CheckedModel):
    """A box standing on the ground.

    Attributes:
        center: Centre of its footprint (x, y) [m].
        size: Full lengths along its x and y and its height [m].
        yaw: Heading of its x axis [rad].
    """

    center: tuple[Coordinate, Coordinate]
    size: tuple[Length, Length, Height]
    yaw: Angle = 0.0

    def corners(self) -> Array:
        """Footprint corners (x, y) [m], counter-clockwise, shape (4, 2)."""
        hx, hy = 0.5 * self.size[0], 0.5 * self.size[1]
        local = np.array([[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]])
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return local @ np.array([[c, s], [-s, c]]) + np.asarray(self.center)

    def contains(self, xy: Array, margin: float = 0.0) -> NDArray[np.bool_]:
        """Whether points (x, y) [m], shape (n, 2), lie within ``margin`` [m] of the footprint."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        d = np.atleast_2d(xy) - np.asarray(self.center)
        local = np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])
        outside = np.maximum(np.abs(local) - 0.5 * np.asarray(self.size[:2]), 0.0)
        return np.hypot(outside[:, 0], outside[:, 1]) <= margin

    def moved(self, center: tuple[float, float], yaw: float) -> Box:
        return Box(center=center, size=self.size, yaw=yaw)


class Course(CheckedModel):
    """A checked, immutable obstacle course."""

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9._-]*$")
    description: str = ""
    duration: RideDuration
    start: tuple[Coordinate, Coordinate, Angle] = (0.0, 0.0, 0.0)
    goal: tuple[Coordinate, Coordinate]
    goal_tolerance: Annotated[Real, Field(gt=0.0, le=2.0)] = 0.3  # [m]
    robots: tuple[str, ...] = ()  # robots it applies to; empty means any
    boards: tuple[str, ...] = ()  # boards it applies to; empty means any
    obstacles: tuple[Box, ...] = ()
    terrain: tuple[TerrainItem, ...] = ()  # in the start's frame; see ridempc.scenarios.terrain

    @model_validator(mode="after")
    def _terrain_fits(self) -> Course:
        check_terrain(self.terrain)
        return self

    @model_validator(mode="after")
    def _clear_ends(self) -> Course:
        start = np.asarray(self.start[:2])
        for i, box in enumerate(self.obstacles):
            if box.contains(np.asarray(self.goal), margin=self.goal_tolerance)[0]:
                raise ValueError(
                    f"goal {list(self.goal)} is inside obstacles.{i} (or within the goal "
                    f"tolerance {self.goal_tolerance} m of it); allowed: a goal in free space"
                )
            if box.contains(start, margin=0.5)[0]:
                raise ValueError(
                    f"start {list(self.start[:2])} is within 0.5 m of obstacles.{i}; "
                    "allowed: a start with room for the rider"
                )
        return self

    def applies_to(self, robot: str, board: str) -> bool:
        return (not self.robots or robot in self.robots) and (
            not self.boards or board in self.boards
        )

    def in_start_frame(self) -> Course:
        """The course seen from its start: start at the origin heading along x."""
        x0, y0, yaw0 = self.start
        c, s = math.cos(yaw0), math.sin(yaw0)

        def local(xy: tuple[float, float]) -> tuple[float, float]:
            dx, dy = xy[0] - x0, xy[1] - y0
            return (c * dx + s * dy, -s * dx + c * dy)

        return self.model_copy(
            update={
                "start": (0.0, 0.0, 0.0),
                "goal": local(self.goal),
                "obstacles": tuple(
                    b.moved(local(b.center), math.remainder(b.yaw - yaw0, 2.0 * math.pi))
                    for b in self.obstacles
                ),
            }
        )


def course_names() -> tuple[str, ...]:
    return tuple(sorted(p.stem for p in COURSE_DIR.glob("*.toml")))


def load_course(path: Path) -> Course:
    """Read and check a course file.

    Raises:
        ConfigError: Missing file, not TOML, or a bad field (named in the message).
    """
    return load_checked(path, Course, "course file")


def resolve_course(name_or_path: str) -> Course:
    """A course by library name, or from a ``.toml`` path.

    Raises:
        UnknownNameError: Not a library name and not a ``.toml`` path.
        ConfigError: A malformed file.
    """
    if name_or_path.lower().endswith(".toml") or "/" in name_or_path:
        return load_course(Path(name_or_path))
    if name_or_path not in course_names():
        raise UnknownNameError("course", name_or_path, course_names())
    return load_course(COURSE_DIR / f"{name_or_path}.toml")
