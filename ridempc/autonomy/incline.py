r"""The incline ahead of the rider, measured on the map's ground (never the scene).

The occupancy grid keeps each cell's ground height (:class:`~ridempc.autonomy.occupancy.
OccupancyGrid`, from the segmented ground points). Sampled every cell along the rider's
heading from ``behind`` the base to ``reach`` ahead, the heights are fitted by a line over
each ``WINDOW`` of the samples; the incline is the steepest of those fits,

.. math:: \alpha = \max_w \left| \arctan \frac{\mathrm{d}z}{\mathrm{d}s} \right|_w \quad [rad],

so a ramp that begins ahead is measured before the shoes roll onto it. The cells within a
cell of an obstacle are left out: the lower part of a box's face, under the segmentation's
obstacle height, reads as ground rising steeply.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.occupancy import GridFrame

__all__ = ["MIN_SAMPLES", "WINDOW", "incline_ahead"]

Array = NDArray[np.float64]

# [m] A fit's length: ten 5 cm cells average the ground's depth noise (0.004 z^2, under
# 0.01 m within 1.5 m) down to a tenth of a 7 deg ramp's rise over it (0.06 m).
WINDOW: float = 0.5
MIN_SAMPLES: int = 5  # cells with ground in a window for its fit: half of them


def incline_ahead(
    frame: GridFrame,
    ground: Array,
    position: Array,
    heading: float,
    reach: float,
    behind: float,
    occupied: NDArray[np.bool_] | None = None,
) -> float:
    """The steepest incline [rad] of the map's ground along ``heading`` [rad] from
    ``behind`` [m] the rider's ``position`` (x, y) [m] to ``reach`` [m] ahead of it; 0 where
    too little ground was seen. The ground within a cell of ``occupied`` is not used."""
    s = np.arange(-behind, reach + 0.5 * frame.resolution, frame.resolution)
    xy = np.asarray(position, dtype=float)[:2] + s[:, None] * [math.cos(heading), math.sin(heading)]
    ij, inside = frame.cells(xy)
    z = np.full(len(s), np.nan)
    z[inside] = ground[ij[inside, 0], ij[inside, 1]]
    if occupied is not None:
        i, j = ij[inside, 0], ij[inside, 1]
        near = np.zeros(len(i), dtype=bool)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                ni = np.clip(i + di, 0, frame.shape[0] - 1)
                nj = np.clip(j + dj, 0, frame.shape[1] - 1)
                near |= occupied[ni, nj]
        z[inside] = np.where(near, np.nan, z[inside])
    width = max(2, round(WINDOW / frame.resolution))
    steepest = 0.0
    for first in range(0, max(1, len(s) - width + 1)):
        window = slice(first, first + width)
        seen = np.isfinite(z[window])
        if seen.sum() < MIN_SAMPLES:
            continue
        slope = np.polyfit(s[window][seen], z[window][seen], 1)[0]
        steepest = max(steepest, abs(math.atan(slope)))
    return steepest
