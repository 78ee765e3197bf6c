"""The global planner: Dijkstra over the inflated costmap, 8-connected.

Moving between neighbouring cells costs their distance times :math:`1 + w \\bar c`, with
:math:`\\bar c` the mean of the two cells' costs (:mod:`ridempc.autonomy.costmap`) and
:math:`w` the weight of cost against length; lethal cells are not in the graph. The
search runs in SciPy's compiled ``csgraph.dijkstra``; :func:`plan_heapq` is the same search
in pure Python, the reference it is tested against (about 10 times slower, measured in
``ridempc navigate --bench``).
"""

from __future__ import annotations

import heapq
import math

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from ridempc.autonomy.costmap import Costmap
from ridempc.errors import RidempcError

__all__ = ["COST_WEIGHT", "NoPath", "plan", "plan_heapq"]

Array = NDArray[np.float64]

COST_WEIGHT: float = 2.0  # a cell next to the inscribed radius costs as much as 3 free ones
_NEIGHBOURS = ((1, 0), (0, 1), (1, 1), (1, -1))  # each undirected edge once


class NoPath(RidempcError):
    """No path from the start to the goal on the costmap."""


def _cell(costmap: Costmap, xy: Array, what: str) -> tuple[int, int]:
    ij, inside = costmap.frame.cells(np.asarray(xy, dtype=float).reshape(1, 2))
    if not inside[0]:
        raise NoPath(f"the {what} ({xy[0]:.2f}, {xy[1]:.2f}) m is outside the map")
    i, j = int(ij[0, 0]), int(ij[0, 1])
    if not np.isfinite(costmap.cost[i, j]):
        raise NoPath(
            f"the {what} ({xy[0]:.2f}, {xy[1]:.2f}) m is within the rider's radius of an obstacle"
        )
    return i, j


def _edges(cost: Array, resolution: float, weight: float) -> tuple[Array, Array, Array]:
    """Both directions of every edge between free neighbours: (from, to, length)."""
    shape = cost.shape
    index = np.arange(cost.size).reshape(shape)
    free = np.isfinite(cost)
    rows, cols, weights = [], [], []
    for di, dj in _NEIGHBOURS:
        a = (slice(0, shape[0] - di), slice(max(0, -dj), shape[1] - max(0, dj)))
        b = (slice(di, shape[0]), slice(max(0, dj), shape[1] + min(0, dj)))
        ok = free[a] & free[b]
        step = resolution * math.hypot(di, dj)
        w = step * (1.0 + weight * 0.5 * (cost[a] + cost[b]))[ok]
        rows += [index[a][ok], index[b][ok]]
        cols += [index[b][ok], index[a][ok]]
        weights += [w, w]
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)


def plan(costmap: Costmap, start: Array, goal: Array, weight: float = COST_WEIGHT) -> Array:
    """The cheapest path from ``start`` to ``goal`` (world (x, y) [m]): cell centres, shape
    (n, 2) [m], from the start's cell to the goal's.

    Raises:
        NoPath: The start or goal is outside the map or lethal, or no path joins them.
    """
    start_ij = _cell(costmap, start, "start")
    goal_ij = _cell(costmap, goal, "goal")
    cost = costmap.cost
    rows, cols, weights = _edges(cost, costmap.frame.resolution, weight)
    graph = coo_matrix((weights, (rows, cols)), shape=(cost.size, cost.size)).tocsr()
    source = np.ravel_multi_index(start_ij, cost.shape)
    target = np.ravel_multi_index(goal_ij, cost.shape)
    distances, predecessors = dijkstra(
        graph, directed=True, indices=source, return_predecessors=True, min_only=False
    )
    if not np.isfinite(distances[target]):
        raise NoPath(
            f"no path from ({start[0]:.2f}, {start[1]:.2f}) m to ({goal[0]:.2f}, {goal[1]:.2f}) m"
        )
    chain = [int(target)]
    while chain[-1] != source:
        chain.append(int(predecessors[chain[-1]]))
    return _centres(costmap, np.array(chain[::-1]))


def plan_heapq(costmap: Costmap, start: Array, goal: Array, weight: float = COST_WEIGHT) -> Array:
    """:func:`plan` in pure Python with :mod:`heapq` (the reference; slower)."""
    start_ij = _cell(costmap, start, "start")
    goal_ij = _cell(costmap, goal, "goal")
    cost = costmap.cost
    resolution = costmap.frame.resolution
    best = {start_ij: 0.0}
    parent: dict[tuple[int, int], tuple[int, int]] = {}
    queue = [(0.0, start_ij)]
    steps = [(di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]
    while queue:
        d, (i, j) = heapq.heappop(queue)
        if (i, j) == goal_ij:
            break
        if d > best[(i, j)]:
            continue
        for di, dj in steps:
            n = (i + di, j + dj)
            if not (0 <= n[0] < cost.shape[0] and 0 <= n[1] < cost.shape[1]):
                continue
            c = cost[n]
            if not math.isfinite(c):
                continue
            nd = d + resolution * math.hypot(di, dj) * (1.0 + weight * 0.5 * (cost[i, j] + c))
            if nd < best.get(n, math.inf):
                best[n] = nd
                parent[n] = (i, j)
                heapq.heappush(queue, (nd, n))
    if goal_ij not in best:
        raise NoPath(
            f"no path from ({start[0]:.2f}, {start[1]:.2f}) m to ({goal[0]:.2f}, {goal[1]:.2f}) m"
        )
    chain = [goal_ij]
    while chain[-1] != start_ij:
        chain.append(parent[chain[-1]])
    flat = np.ravel_multi_index(tuple(np.array(chain[::-1]).T), cost.shape)
    return _centres(costmap, flat)


def _centres(costmap: Costmap, flat: NDArray[np.int64]) -> Array:
    i, j = np.unravel_index(flat, costmap.cost.shape)
    frame = costmap.frame
    return np.column_stack(
        [
            frame.origin[0] + (i + 0.5) * frame.resolution,
            frame.origin[1] + (j + 0.5) * frame.resolution,
        ]
    )
