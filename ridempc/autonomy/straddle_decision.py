"""The decision to straddle, kept across replans: made from a group's measured size once it
is seen well enough, held with hysteresis, never from a first glimpse.

At the fusing range a low box shows a few cells of its front face, speckled; a lone cell
unhit beside them, or a top that noise lifts for one frame, must not send the path round it
and then back. Each replan measures the map's groups of occupied cells
(:func:`~ridempc.autonomy.straddle.measure_groups`) and sorts them:

================================  ===========================================================
group                             is
================================  ===========================================================
decided a straddle before         a straddle while at most ``max_height + height_margin``
(overlapping its cells)           tall and ``max_width + width_margin`` wide; else an obstacle
within ``decide_range``           decided now: a straddle if it :func:`fits` the limits,
                                  else an obstacle
farther                           a straddle (not yet decided) if it fits; a speck of fewer
                                  than ``min_cells`` low cells is ignored (neither ridden
                                  round nor straddled); else an obstacle
================================  ===========================================================

So the path lines up with a low box from its first sighting, the feet spread only once it
is decided (:class:`~ridempc.autonomy.navigator.Navigator` spreads within ``lead``, inside
the deciding range), and a box that proves too big is ridden round from ``decide_range``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import binary_dilation

from ridempc.autonomy.occupancy import GridFrame
from ridempc.autonomy.straddle import Straddle, StraddleSettings, fits, measure_groups

__all__ = ["StraddleDecision", "StraddleTracker"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class StraddleDecision:
    """One replan's sorting of the map's low groups.

    Attributes:
        straddles: Groups passed between the feet (decided, or taken as such from afar).
        ignored: Cells of far specks: neither obstacles nor lanes yet.
    """

    straddles: tuple[Straddle, ...]
    ignored: NDArray[np.bool_]


class StraddleTracker:
    """Sorts each replan's groups (the module docstring), remembering the decided straddles.

    Args:
        settings: What can be straddled, and the decision's range and margins.
    """

    def __init__(self, settings: StraddleSettings) -> None:
        self.settings = settings
        self._decided: NDArray[np.bool_] | None = None  # cells of the decided straddles

    def update(
        self,
        frame: GridFrame,
        occupied: NDArray[np.bool_],
        height: Array,
        rider: Array,
    ) -> StraddleDecision:
        """Sort the groups of the map seen from ``rider`` (x, y) [m].

        Args:
            frame: The grid's geometry.
            occupied: Occupied cells.
            height: Tallest obstacle point seen in each cell, over the ground [m].
            rider: The rider's position (x, y) [m].
        """
        s = self.settings
        keep_height, keep_width = s.max_height + s.height_margin, s.max_width + s.width_margin
        groups = measure_groups(frame, occupied, height, s, rider, keep_height, keep_width)
        decided = self._decided
        if decided is not None and decided.shape == frame.shape:
            join = round(s.join / frame.resolution)
            decided = binary_dilation(decided, np.ones((2 * join + 1,) * 2, dtype=bool))
        else:
            decided = np.zeros(frame.shape, dtype=bool)
        x, y = frame.centers()
        straddles, ignored = [], np.zeros(frame.shape, dtype=bool)
        now_decided = np.zeros(frame.shape, dtype=bool)
        for group in groups:
            if (group.cells & decided).any():
                if fits(group, keep_height, keep_width, 1):
                    straddles.append(group)
                    now_decided |= group.cells
                continue
            cells = group.cells
            near = float(np.hypot(x[cells] - rider[0], y[cells] - rider[1]).min()) <= (
                s.decide_range
            )
            if fits(group, s.max_height, s.max_width, s.min_cells):
                straddles.append(group)
                if near:
                    now_decided |= cells
            elif not near and group.height <= s.max_height and int(cells.sum()) < s.min_cells:
                ignored |= cells
        self._decided = now_decided
        return StraddleDecision(tuple(straddles), ignored)
