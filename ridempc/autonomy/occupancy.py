"""A global log-odds occupancy grid, registered with the estimated pose.

Each frame adds :math:`l_{occ}` to the cells holding obstacle points and :math:`l_{free}` to
the cells the sensor saw through: the cells of observed ground, and the cells a ray to any
observed point crosses *below* ``clear_height`` (a ray that high over a cell proves that no
obstacle that tall stands there; higher up it proves nothing about a low box). The log-odds
are clamped so that a cell can change its mind within a few frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["GridFrame", "OccupancyGrid"]

Array = NDArray[np.float64]

L_OCCUPIED: float = 0.85  # log-odds of a hit: p = 0.7 per frame
L_FREE: float = -0.4  # log-odds of a pass-through: p = 0.4 per frame
L_MIN, L_MAX = -2.0, 3.5  # clamps: about five frames to flip a cell
CLEAR_HEIGHT: float = 0.08  # [m] the ground test's obstacle height


@dataclass(frozen=True)
class GridFrame:
    """The geometry of a 2-D grid: cell ``(i, j)`` covers
    ``origin + (i, j) * resolution`` to ``+ resolution`` in world (x, y) [m]."""

    origin: tuple[float, float]
    resolution: float
    shape: tuple[int, int]

    def cells(self, xy: Array) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
        """Integer cells of world points, shape (n, 2), and which fall inside the grid."""
        ij = np.floor((xy - np.asarray(self.origin)) / self.resolution).astype(np.int64)
        inside = (ij >= 0).all(axis=1) & (ij[:, 0] < self.shape[0]) & (ij[:, 1] < self.shape[1])
        return ij, inside

    def centers(self) -> tuple[Array, Array]:
        """World x and y of the cell centres, each of ``shape``."""
        x = self.origin[0] + (np.arange(self.shape[0]) + 0.5) * self.resolution
        y = self.origin[1] + (np.arange(self.shape[1]) + 0.5) * self.resolution
        return np.meshgrid(x, y, indexing="ij")


class OccupancyGrid:
    """Log-odds occupancy over a fixed world window.

    Args:
        frame: The grid's geometry.
    """

    def __init__(self, frame: GridFrame) -> None:
        self.frame = frame
        self.log_odds = np.zeros(frame.shape)
        self.observed = np.zeros(frame.shape, dtype=bool)
        # tallest obstacle point seen in each cell over the ground [m]; -inf: none seen
        self.height = np.full(frame.shape, -np.inf)
        # the ground's height in each cell [m], the last frame's mean of its ground points,
        # from frames that hit no obstacle in it (a box's lower face reads as ground); NaN:
        # never seen
        self.ground = np.full(frame.shape, np.nan)

    def update(
        self, sensor: Array, ground: Array, obstacles: Array, heights: Array | None = None
    ) -> None:
        """Fuse one frame's segmented points.

        Args:
            sensor: Camera position in the world [m], (3,).
            ground: Ground points [m], shape (n, 3).
            obstacles: Obstacle points [m], shape (m, 3).
            heights: Each obstacle point's height over the ground under it [m], (m,).
        """
        frame = self.frame
        free = np.zeros(frame.shape, dtype=bool)
        hit = np.zeros(frame.shape, dtype=bool)
        ij, inside = self._ray_cells(sensor, ground)  # a ray to an obstacle clears no floor
        free[ij[inside, 0], ij[inside, 1]] = True
        ij, inside = frame.cells(obstacles[:, :2])
        hit[ij[inside, 0], ij[inside, 1]] = True
        on, below = frame.cells(ground[:, :2])
        free[on[below, 0], on[below, 1]] = True
        below[below] &= ~hit[on[below, 0], on[below, 1]]
        self._fuse_ground(on[below], ground[below, 2])
        if heights is not None:
            np.maximum.at(self.height, (ij[inside, 0], ij[inside, 1]), heights[inside])
        free &= ~hit
        self.log_odds[free] += L_FREE
        self.log_odds[hit] += L_OCCUPIED
        np.clip(self.log_odds, L_MIN, L_MAX, out=self.log_odds)
        self.observed |= free | hit

    def _fuse_ground(self, ij: NDArray[np.int64], z: Array) -> None:
        """Each cell's ground height [m] from this frame's ground points in it."""
        flat = np.ravel_multi_index((ij[:, 0], ij[:, 1]), self.frame.shape)
        count = np.bincount(flat, minlength=self.ground.size)
        total = np.bincount(flat, weights=z, minlength=self.ground.size)
        seen = count > 0
        self.ground.reshape(-1)[seen] = total[seen] / count[seen]

    def _ray_cells(
        self, sensor: Array, points: Array
    ) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
        """Cells crossed, below ``CLEAR_HEIGHT`` over each ray's end (a ground point), by the
        rays from the sensor to ``points``, short of the end's own cell."""
        if len(points) == 0:
            return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=bool)
        drop = sensor[2] - points[:, 2]  # > 0: the camera looks down
        # the part of the ray within CLEAR_HEIGHT of its end: fraction s in [1 - f, 1)
        fraction = np.clip(CLEAR_HEIGHT / np.maximum(drop, 1e-6), 0.0, 1.0)
        length = np.linalg.norm(points[:, :2] - sensor[:2], axis=1) * fraction
        step = 0.5 * self.frame.resolution
        count = int(np.ceil(length.max() / step)) + 1 if len(length) else 1
        s = 1.0 - fraction[:, None] * (1.0 - np.arange(count)[None, :] / count)
        within = np.arange(count)[None, :] * step < length[:, None]
        xy = sensor[None, None, :2] + s[..., None] * (points[:, None, :2] - sensor[None, None, :2])
        xy = xy[within]
        ij, inside = self.frame.cells(xy)
        end, _ = self.frame.cells(points[:, :2])
        ends = np.repeat(end, within.sum(axis=1), axis=0)
        inside &= (ij != ends).any(axis=1)
        return ij, inside

    def probability(self) -> Array:
        """Occupancy probability of each cell."""
        return 1.0 / (1.0 + np.exp(-self.log_odds))

    def occupied(self, threshold: float = 0.0) -> NDArray[np.bool_]:
        """Cells whose log-odds exceed ``threshold`` (0: more likely occupied than free)."""
        return self.log_odds > threshold
