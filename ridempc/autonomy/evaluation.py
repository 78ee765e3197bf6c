"""Perception judged against the scene's true obstacles, rasterised from the course's boxes.

An occupied cell is a true positive when it lies within one cell of a box's footprint (the
rasterisation of an edge is ambiguous by a cell); a box cell is found when an occupied cell
lies within one cell of it. Both are counted within ``radius`` of the ridden path, over the
cells the camera observed (the far side of a box is never seen).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import binary_dilation

from ridempc.autonomy.course import Box
from ridempc.autonomy.occupancy import GridFrame

__all__ = ["CellScores", "rasterise", "score_cells"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class CellScores:
    """Obstacle-cell precision and recall, and the share of false obstacle cells."""

    precision: float
    recall: float
    false_share: float
    occupied: int
    true: int


def rasterise(
    frame: GridFrame, boxes: tuple[Box, ...] | list[Box], margin: float = 0.0
) -> NDArray[np.bool_]:
    """Cells whose centre lies within ``margin`` [m] of a box's footprint."""
    x, y = frame.centers()
    xy = np.column_stack([x.reshape(-1), y.reshape(-1)])
    inside = np.zeros(len(xy), dtype=bool)
    for box in boxes:
        inside |= box.contains(xy, margin)
    return inside.reshape(frame.shape)


def score_cells(
    frame: GridFrame,
    occupied: NDArray[np.bool_],
    observed: NDArray[np.bool_],
    boxes: tuple[Box, ...] | list[Box],
    path: Array,
    radius: float = 3.0,
) -> CellScores:
    """Precision, recall and false share of ``occupied`` within ``radius`` [m] of ``path``
    (world (x, y) [m], shape (n, 2))."""
    x, y = frame.centers()
    near = np.zeros(frame.shape, dtype=bool)
    for px, py in path[:: max(1, len(path) // 200)]:
        near |= np.hypot(x - px, y - py) <= radius
    truth = rasterise(frame, boxes)
    counted = near & observed
    ring = binary_dilation(truth, iterations=1)
    found = binary_dilation(occupied, iterations=1)
    occ = occupied & counted
    tru = truth & counted
    precision = float((occ & ring).sum() / occ.sum()) if occ.sum() else 1.0
    recall = float((tru & found).sum() / tru.sum()) if tru.sum() else 1.0
    free = counted & ~ring
    false_share = float((occ & free).sum() / free.sum()) if free.sum() else 0.0
    return CellScores(precision, recall, false_share, int(occ.sum()), int(tru.sum()))
