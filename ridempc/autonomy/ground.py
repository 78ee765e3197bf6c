"""Ground segmentation that holds on slopes and steps: a height test per 5 cm column.

One global plane fails on a slope or a step. Here each column of the voxel grid keeps its
lowest point :math:`z_{min}(c)`, and the ground under column :math:`c` is the lowest
surface reachable from any observed column by climbing no steeper than ``max_slope``:

.. math:: g(c) = \\min_{c'} \\left( z_{min}(c')
    + \\tan(\\alpha_{max}) \\, \\lVert c - c' \\rVert \\right),

a grey-scale erosion with a cone, computed by min-plus propagation over the 8-neighbours
(a chamfer distance; exact to 8 % on diagonals). On a slope below :math:`\\alpha_{max}` the
ground is the column's own lowest point; a step lower than ``obstacle_height`` stays ground.
A point is an obstacle when it stands more than ``obstacle_height`` over :math:`g(c)`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["GroundSplit", "segment_ground"]

Array = NDArray[np.float64]

MAX_SLOPE: float = math.radians(18.0)  # the terrain issue's steepest slope (13 deg) and margin
OBSTACLE_HEIGHT: float = 0.08  # [m] over the ground: the lowest box a hovershoe cannot roll over
SEARCH_RADIUS: float = 1.2  # [m] how far a column looks for lower ground (a box's half-width)


@dataclass(frozen=True)
class GroundSplit:
    """Points split into ground and obstacles, with each point's height over the ground.

    Attributes:
        ground: Ground points [m], shape (n, 3).
        obstacles: Obstacle points [m], shape (m, 3).
        obstacle_heights: Height of each obstacle point over the ground under it [m].
    """

    ground: Array
    obstacles: Array
    obstacle_heights: Array


def segment_ground(
    points: Array,
    cell: float = 0.05,
    max_slope: float = MAX_SLOPE,
    obstacle_height: float = OBSTACLE_HEIGHT,
    search_radius: float = SEARCH_RADIUS,
) -> GroundSplit:
    """Split world points (voxel-filtered) into ground and obstacles.

    Args:
        points: World points [m], shape (n, 3).
        cell: Column size [m] (the voxels' horizontal size).
        max_slope: Steepest ground [rad].
        obstacle_height: Height over the ground from which a point is an obstacle [m].
        search_radius: How far the propagation reaches [m].
    """
    if len(points) == 0:
        empty = np.zeros((0, 3))
        return GroundSplit(empty, empty, np.zeros(0))
    ij = np.floor(points[:, :2] / cell).astype(np.int64)
    lo = ij.min(axis=0)
    ij -= lo
    shape = tuple(ij.max(axis=0) + 1)
    lowest = np.full(shape, np.inf)
    np.minimum.at(lowest, (ij[:, 0], ij[:, 1]), points[:, 2])
    ground = _cone_erosion(lowest, math.tan(max_slope) * cell, round(search_radius / cell))
    height = points[:, 2] - ground[ij[:, 0], ij[:, 1]]
    is_obstacle = height > obstacle_height
    return GroundSplit(points[~is_obstacle], points[is_obstacle], height[is_obstacle])


def _cone_erosion(lowest: Array, rise: float, steps: int) -> Array:
    """Min-plus propagation of ``lowest`` with ``rise`` per cell step (diagonals x sqrt 2)."""
    ground = lowest.copy()
    diagonal = rise * math.sqrt(2.0)
    padded = np.full((ground.shape[0] + 2, ground.shape[1] + 2), np.inf)
    for _ in range(steps):
        padded[1:-1, 1:-1] = ground
        before = ground
        ground = ground.copy()
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                if di == 0 and dj == 0:
                    continue
                shifted = padded[
                    1 + di : padded.shape[0] - 1 + di, 1 + dj : padded.shape[1] - 1 + dj
                ]
                np.minimum(ground, shifted + (diagonal if di and dj else rise), out=ground)
        if np.array_equal(ground, before):
            break
    return ground
