"""One global replan: the costmap of the map, the straddles' lanes in it, Dijkstra's path.

The navigator calls :func:`plan_global` at ``global_hz`` and ``ridempc navigate --bench``
times the same call. The occupied cells are inflated into the costmap; a straddle's cells
(:mod:`ridempc.autonomy.straddle`) are not obstacles but lethal around them outside their
lane (far specks of low cells neither, :mod:`ridempc.autonomy.straddle_decision`); the
cells never seen cost ``unknown_cost`` more; the search runs on cells
``global_coarsening`` times coarser, and the path is snapped onto the straddles' axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.costmap import Costmap, inflate
from ridempc.autonomy.dijkstra import plan
from ridempc.autonomy.occupancy import GridFrame
from ridempc.autonomy.straddle import Straddle, onto_axes, straddle_lethal
from ridempc.autonomy.straddle_decision import StraddleTracker
from ridempc.autonomy.teb import LOOK_AHEAD

if TYPE_CHECKING:
    from ridempc.autonomy.navigator import NavigatorSettings

__all__ = ["GlobalPlan", "plan_global"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class GlobalPlan:
    """A global plan.

    Attributes:
        path: Cell centres (x, y) from the start to the goal [m], shape (n, 2).
        costmap: The (coarsened) costmap it was searched on.
        straddles: The obstacles it passes between the feet, if its path crosses them.
        ignored: Occupied cells it neither rides round nor straddles (far specks).
    """

    path: Array
    costmap: Costmap
    straddles: tuple[Straddle, ...]
    ignored: NDArray[np.bool_]


def plan_global(
    frame: GridFrame,
    occupied: NDArray[np.bool_],
    height: Array,
    observed: NDArray[np.bool_],
    start: Array,
    goal: Array,
    settings: NavigatorSettings,
    tracker: StraddleTracker | None = None,
) -> GlobalPlan:
    """The global plan from ``start`` to ``goal`` (x, y) [m] over the map.

    Args:
        frame: The map's geometry.
        occupied: Its occupied cells.
        height: Tallest obstacle point seen in each cell, over the ground [m].
        observed: The cells ever seen.
        start: Where the rider is [m].
        goal: The goal [m].
        settings: The navigator's settings.
        tracker: The ride's straddle decisions so far (None: decided afresh from this map).

    Raises:
        NoPath: The goal cannot be reached.
    """
    s = settings
    tracker = tracker if tracker is not None else StraddleTracker(s.straddle)
    decision = tracker.update(frame, occupied, height, start)
    straddles = decision.straddles
    obstacles = occupied & ~decision.ignored
    for straddle in straddles:
        obstacles &= ~straddle.cells
    costmap = inflate(frame, obstacles, s.inscribed, s.decay)
    # the global planner's cells are coarser than the lane: it gets one of them more
    lane = s.straddle.lane + s.global_coarsening * frame.resolution
    costmap.cost[straddle_lethal(frame, straddles, s.inscribed, lane)] = np.inf
    costmap.cost[~observed] += s.unknown_cost
    costmap = costmap.coarsened(s.global_coarsening)
    path = plan(costmap, _free_start(costmap, start), goal)
    # the local goal stays on the axis while the rider is in the lane
    path = onto_axes(path, straddles, s.inscribed + LOOK_AHEAD, lane)
    return GlobalPlan(path, costmap, straddles, decision.ignored)


def _free_start(costmap: Costmap, start: Array) -> Array:
    """The start, or the nearest cell outside the inscribed radius when the rider stands
    within it (a noisy map next to a box): the rider gets out the cheapest way."""
    if not costmap.lethal_at(start):
        return start
    x, y = costmap.frame.centers()
    free = np.isfinite(costmap.cost)
    if not free.any():
        return start
    d = np.hypot(x - start[0], y - start[1])
    d[~free] = np.inf
    k = np.unravel_index(int(np.argmin(d)), d.shape)
    return np.array([x[k], y[k]])
