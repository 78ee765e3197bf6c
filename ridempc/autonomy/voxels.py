"""Voxel filter: a point cloud thinned to one point per voxel (the paper's 5 x 5 x 10 cm).

Each occupied voxel keeps the centroid of its points, so a plane keeps its height to within
the noise rather than to the voxel's 10 cm, and the ground test downstream stays exact on
slopes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["VOXEL_SIZE", "voxel_filter"]

Array = NDArray[np.float64]

VOXEL_SIZE: tuple[float, float, float] = (0.05, 0.05, 0.10)  # [m] the Hovershoes paper, sec. V


def voxel_filter(points: Array, size: tuple[float, float, float] = VOXEL_SIZE) -> Array:
    """The centroid of the points in each occupied voxel, shape (voxels, 3) [m].

    Args:
        points: World points [m], shape (n, 3).
        size: Voxel edge lengths (x, y, z) [m].
    """
    if len(points) == 0:
        return np.zeros((0, 3))
    keys = np.floor(points / np.asarray(size)).astype(np.int64)
    keys -= keys.min(axis=0)
    flat = np.ravel_multi_index(keys.T, tuple(keys.max(axis=0) + 1))  # one integer per voxel
    _, inverse, counts = np.unique(flat, return_inverse=True, return_counts=True)
    sums = np.column_stack(
        [np.bincount(inverse, weights=points[:, k], minlength=len(counts)) for k in range(3)]
    )
    return sums / counts[:, None]
