"""A course's boxes in the MuJoCo scene: static world geoms, colliding like the floor."""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np

from ridempc.autonomy.course import Box

__all__ = ["OBSTACLE_PREFIX", "add_obstacles", "obstacle_geoms", "place_obstacles"]

OBSTACLE_PREFIX = "course/obstacle_"
OBSTACLE_RGBA: tuple[float, float, float, float] = (0.85, 0.45, 0.15, 1.0)


def add_obstacles(spec: mujoco.MjSpec, boxes: tuple[Box, ...]) -> None:
    """Add the boxes to the world body of a model spec (at their course position)."""
    for i, box in enumerate(boxes):
        half = [0.5 * box.size[0], 0.5 * box.size[1], 0.5 * box.size[2]]
        spec.worldbody.add_geom(
            name=f"{OBSTACLE_PREFIX}{i}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=half,
            pos=[box.center[0], box.center[1], half[2]],
            quat=[math.cos(box.yaw / 2), 0.0, 0.0, math.sin(box.yaw / 2)],
            rgba=list(OBSTACLE_RGBA),
            contype=1,
            conaffinity=3,
            condim=3,
        )


def obstacle_geoms(model: mujoco.MjModel) -> list[int]:
    """Geom ids of the course's boxes."""
    return [
        g
        for g in range(model.ngeom)
        if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "").startswith(OBSTACLE_PREFIX)
    ]


def place_obstacles(
    model: mujoco.MjModel, shift: np.ndarray, level: Callable[[float], float] | None = None
) -> None:
    """Move the boxes by ``shift`` (x, y) [m]: the course's start frame onto the rider's
    starting base, which the scene builder places; and each onto the ground's ``level`` [m]
    at its world x (the terrain's profile), if given."""
    for g in obstacle_geoms(model):
        model.geom_pos[g, :2] += shift
        if level is not None:
            model.geom_pos[g, 2] += level(float(model.geom_pos[g, 0]))
