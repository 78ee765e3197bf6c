"""The perception pipeline of one depth frame: points, voxels, ground, map, scan.

depth image --(estimated camera pose)--> world points --> voxel filter (5 x 5 x 10 cm)
--> ground segmentation --> global occupancy grid and a pseudo-laser scan. Points within
``self_radius`` of the estimated base are the rider and its board, not obstacles; depths
beyond ``fuse_range`` are not fused.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.camera import to_points
from ridempc.autonomy.ground import segment_ground
from ridempc.autonomy.occupancy import OccupancyGrid
from ridempc.autonomy.scan import Scan, pseudo_scan
from ridempc.autonomy.voxels import voxel_filter

__all__ = ["Perception", "PerceivedFrame"]

Array = NDArray[np.float64]

SELF_RADIUS: float = 0.45  # [m] Cassie's stance on the shoes seen from the pelvis, with margin
# [m] Stereo depth's sigma = 0.004 z^2 is 0.036 m at 3 m, most of a 5 cm cell: farther, the
# top of a wall reads cells behind its far face, which no later ray clears (the camera never
# sees the ground there).
FUSE_RANGE: float = 3.0


@dataclass(frozen=True)
class PerceivedFrame:
    """What one frame gave.

    Attributes:
        ground: Ground voxels [m], shape (n, 3).
        obstacles: Obstacle voxels [m], shape (m, 3).
        scan: The pseudo-laser scan.
        elapsed: Wall time of the pipeline [s].
    """

    ground: Array
    obstacles: Array
    scan: Scan
    elapsed: float


class Perception:
    """Fuses frames into ``grid``.

    Args:
        grid: The global occupancy grid.
        rays: The camera's :func:`~ridempc.autonomy.camera.pixel_rays`.
        fov: The camera's horizontal field of view [rad] (the scan's width).
        self_radius: Points this close to the base, horizontally, are the rider [m].
        fuse_range: Depths beyond this are left out [m].
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        rays: Array,
        fov: float,
        self_radius: float = SELF_RADIUS,
        fuse_range: float = FUSE_RANGE,
    ) -> None:
        self.grid = grid
        self.rays = rays
        self.fov = fov
        self.self_radius = self_radius
        self.fuse_range = fuse_range

    def update(
        self, depth: Array, rotation: Array, position: Array, base: Array, yaw: float
    ) -> PerceivedFrame:
        """Fuse one frame.

        Args:
            depth: Depth image [m] (0: nothing seen).
            rotation: Estimated camera-to-world rotation.
            position: Estimated camera position [m].
            base: Estimated base position [m].
            yaw: Estimated heading [rad].
        """
        began = time.perf_counter()
        depth = np.where(depth <= self.fuse_range, depth, 0.0)  # 0: nothing seen
        points = to_points(depth, self.rays, rotation, position)
        away = np.hypot(points[:, 0] - base[0], points[:, 1] - base[1]) > self.self_radius
        voxels = voxel_filter(points[away])
        split = segment_ground(voxels)
        self.grid.update(position, split.ground, split.obstacles, split.obstacle_heights)
        scan = pseudo_scan(split.obstacles, base[:2], yaw, self.fov)
        return PerceivedFrame(split.ground, split.obstacles, scan, time.perf_counter() - began)
