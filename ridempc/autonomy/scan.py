"""A pseudo-laser scan: the nearest obstacle per bearing, from one frame's obstacle points.

The fast local map of the paper: what the camera sees now, independent of the global map's
registration, as ranges over bearings in the rider's heading frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Scan", "pseudo_scan"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Scan:
    """Ranges per bearing.

    Attributes:
        bearings: Beam directions relative to the heading [rad], ascending.
        ranges: Distance to the nearest obstacle point per beam [m], ``inf`` for none.
        origin: Scan origin in the world (x, y) [m].
        yaw: Heading of the scan [rad].
    """

    bearings: Array
    ranges: Array
    origin: Array
    yaw: float

    def points(self) -> Array:
        """World (x, y) of the beams that hit, shape (n, 2) [m]."""
        hit = np.isfinite(self.ranges)
        angle = self.yaw + self.bearings[hit]
        r = self.ranges[hit]
        return self.origin + np.column_stack([r * np.cos(angle), r * np.sin(angle)])


def pseudo_scan(
    obstacles: Array, origin: Array, yaw: float, fov: float, beams: int = 90, max_range: float = 4.0
) -> Scan:
    """The nearest obstacle per bearing within ``fov`` [rad] around ``yaw`` [rad].

    Args:
        obstacles: Obstacle points [m], shape (n, >= 2).
        origin: Scan origin (x, y) [m].
        yaw: Heading [rad].
        fov: Angular width of the scan [rad].
        beams: Number of beams.
        max_range: Farther points are dropped [m].
    """
    bearings = (np.arange(beams) + 0.5) / beams * fov - 0.5 * fov
    ranges = np.full(beams, np.inf)
    if len(obstacles):
        delta = obstacles[:, :2] - origin[:2]
        distance = np.hypot(delta[:, 0], delta[:, 1])
        bearing = np.angle(np.exp(1j * (np.arctan2(delta[:, 1], delta[:, 0]) - yaw)))
        beam = np.floor((bearing + 0.5 * fov) / fov * beams).astype(np.int64)
        keep = (beam >= 0) & (beam < beams) & (distance <= max_range)
        np.minimum.at(ranges, beam[keep], distance[keep])
    return Scan(bearings, ranges, np.asarray(origin[:2], dtype=float), yaw)
