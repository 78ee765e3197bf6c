"""The inflated costmap: lethal within the rider's inscribed radius, decaying beyond.

As ROS's inflation layer (and the paper), a cell at distance :math:`d` from the nearest
obstacle costs

.. math:: c(d) = \\begin{cases} \\text{lethal} & d \\le r_{in} \\\\
    c_{max} \\, e^{-\\lambda (d - r_{in})} & d > r_{in} \\end{cases}

with :math:`\\lambda` the decay rate [1/m]: a small :math:`\\lambda` keeps the cheapest path
midway between obstacles, a large one lets it graze them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import distance_transform_edt

from ridempc.autonomy.occupancy import GridFrame

__all__ = ["COST_MAX", "Costmap", "inflate"]

Array = NDArray[np.float64]

COST_MAX: float = 1.0  # cost just outside the inscribed radius; lethal cells are inf


class Costmap:
    """Cost per cell (``inf``: lethal) and each cell's distance to the nearest obstacle.

    Attributes:
        frame: The grid's geometry.
        cost: Cost per cell, ``inf`` within the inscribed radius.
        distance: Distance of each cell centre to the nearest obstacle cell [m].
    """

    def __init__(self, frame: GridFrame, cost: Array, distance: Array) -> None:
        self.frame = frame
        self.cost = cost
        self.distance = distance

    def coarsened(self, factor: int) -> Costmap:
        """The costmap on cells ``factor`` times larger: each the most expensive (and the
        closest to an obstacle) of the cells it covers, so no lethal cell is lost."""
        if factor == 1:
            return self
        nx, ny = (n // factor for n in self.cost.shape)
        # one strided slice per offset in the block: a reduction over reshaped axes is
        # several times slower
        cost = self.cost[0 : nx * factor : factor, 0 : ny * factor : factor].copy()
        distance = self.distance[0 : nx * factor : factor, 0 : ny * factor : factor].copy()
        for di in range(factor):
            for dj in range(factor):
                if di or dj:
                    block = (slice(di, nx * factor, factor), slice(dj, ny * factor, factor))
                    np.maximum(cost, self.cost[block], out=cost)
                    np.minimum(distance, self.distance[block], out=distance)
        frame = GridFrame(self.frame.origin, self.frame.resolution * factor, (nx, ny))
        return Costmap(frame, cost, distance)

    def lethal_at(self, xy: Array) -> bool:
        """Whether the world point (x, y) [m] lies in a lethal cell (outside counts so)."""
        ij, inside = self.frame.cells(np.asarray(xy, dtype=float).reshape(1, 2))
        return not inside[0] or not np.isfinite(self.cost[ij[0, 0], ij[0, 1]])


def inflate(
    frame: GridFrame, occupied: NDArray[np.bool_], inscribed: float, decay: float
) -> Costmap:
    """The costmap of an occupancy grid.

    Args:
        frame: The grid's geometry.
        occupied: Occupied cells.
        inscribed: The rider's inscribed radius [m]: closer is a collision.
        decay: Decay rate :math:`\\lambda` of the cost beyond it [1/m].
    """
    if occupied.any():
        distance = distance_transform_edt(~occupied) * frame.resolution
    else:
        distance = np.full(occupied.shape, np.inf)
    cost = COST_MAX * np.exp(-decay * np.maximum(distance - inscribed, 0.0))
    cost[distance <= inscribed] = np.inf
    return Costmap(frame, cost, distance)
