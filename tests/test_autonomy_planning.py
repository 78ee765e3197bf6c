"""Planning on synthetic grids: costmap, Dijkstra (against a heapq reference), the TEB."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc.autonomy.costmap import inflate
from ridempc.autonomy.dijkstra import NoPath, plan, plan_heapq
from ridempc.autonomy.occupancy import GridFrame
from ridempc.autonomy.teb import TebPlanner, TebSettings

FRAME = GridFrame((0.0, -2.0), 0.05, (120, 80))  # 6 m x 4 m


def _walls(gap_y: tuple[float, float] | None = None) -> np.ndarray:
    """A corridor: walls along y = +-1.5 m, and a wall across at x = 3 m with a gap."""
    x, y = FRAME.centers()
    occupied = np.abs(np.abs(y) - 1.5) < 0.05
    if gap_y is not None:
        occupied |= (np.abs(x - 3.0) < 0.05) & ~((y > gap_y[0]) & (y < gap_y[1]))
    return occupied


def _path_length(path: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def test_costmap_is_lethal_within_the_radius_and_decays_beyond() -> None:
    costmap = inflate(FRAME, _walls(), inscribed=0.35, decay=3.0)
    x, y = FRAME.centers()
    column = costmap.cost[60]
    lethal = np.abs(np.abs(y[60]) - 1.5) <= 0.35
    assert np.isinf(column[lethal]).all() and np.isfinite(column[~lethal]).all()
    inner = (y[60] > -1.1) & (y[60] < 0.0)  # from the wall's radius towards the middle
    assert (np.diff(column[inner]) <= 1e-12).all()


@pytest.mark.parametrize("decay", [1.0, 8.0])
def test_dijkstra_matches_the_heapq_reference(decay: float) -> None:
    costmap = inflate(FRAME, _walls((0.2, 1.2)), inscribed=0.35, decay=decay)
    start, goal = np.array([0.5, -0.5]), np.array([5.5, -0.5])
    fast = plan(costmap, start, goal)
    reference = plan_heapq(costmap, start, goal)
    assert _path_length(fast) == pytest.approx(_path_length(reference), rel=0.02)
    through = fast[np.argmin(np.abs(fast[:, 0] - 3.0))]
    assert 0.2 + 0.35 <= through[1] <= 1.2 - 0.35  # through the gap, clear of its sides


def test_a_small_decay_keeps_the_path_midway() -> None:
    occupied = np.zeros(FRAME.shape, dtype=bool)
    x, y = FRAME.centers()
    occupied |= np.abs(y - 1.5) < 0.05
    occupied |= np.abs(y + 0.5) < 0.05  # a corridor from y = -0.5 to 1.5: its middle is 0.5
    start, goal = np.array([0.5, 0.0]), np.array([5.5, 0.0])
    offsets = []
    for decay in (0.5, 30.0):
        path = plan(inflate(FRAME, occupied, 0.35, decay), start, goal)
        middle = path[(path[:, 0] > 2.0) & (path[:, 0] < 4.0)]
        offsets.append(float(np.abs(middle[:, 1] - 0.5).mean()))
    assert offsets[0] < 0.1 < offsets[1]


def test_an_unreachable_goal_is_no_path() -> None:
    costmap = inflate(FRAME, _walls((0.2, 0.5)), inscribed=0.35, decay=3.0)  # gap too narrow
    with pytest.raises(NoPath, match="no path"):
        plan(costmap, np.array([0.5, 0.0]), np.array([5.5, 0.0]))
    with pytest.raises(NoPath, match="within the rider's radius"):
        plan(costmap, np.array([0.5, 0.0]), np.array([3.0, -1.0]))


def test_teb_clears_obstacles_along_its_segments() -> None:
    planner = TebPlanner()
    # a row of points across the straight line: poses may straddle it, segments may not
    wall = np.array([[0.9, y] for y in np.linspace(-0.25, 0.05, 7)])
    start, goal = np.array([0.0, 0.0, 0.0]), np.array([1.75, 0.0, 0.0])
    band = planner.solve(start, goal, wall, speed=0.3)
    assert band.success
    assert np.allclose(band.poses[0], start) and np.allclose(
        band.poses[-1, :2], goal[:2], atol=1e-4
    )
    assert band.clearance(wall) >= planner.settings.d_min - 0.05  # a soft penalty
    speeds, yaw_rates = band.speeds()
    assert (np.abs(speeds) <= planner.settings.v_max + 1e-3).all()
    assert (np.abs(yaw_rates) <= planner.settings.omega_max + 1e-3).all()
    assert (speeds > -1e-3).all()  # forward only
    # non-holonomic: each segment an arc, its chord at the mean of its end headings
    delta = np.diff(band.poses, axis=0)
    chord = np.arctan2(delta[:, 1], delta[:, 0])
    mean_heading = 0.5 * (band.poses[1:, 2] + band.poses[:-1, 2])
    residual = np.abs(np.angle(np.exp(1j * (chord - mean_heading))))
    assert residual.max() < 0.1 and residual.mean() < 0.03


def test_teb_warm_start_agrees_with_a_cold_start() -> None:
    wall = np.array([[1.0, y] for y in np.linspace(0.0, 0.4, 5)])
    start, goal = np.array([0.0, 0.0, 0.0]), np.array([1.75, 0.2, 0.2])
    warm = TebPlanner(TebSettings())
    warm.solve(start, goal, wall)
    again = warm.solve(start, goal, wall)  # from the last band
    cold = TebPlanner(TebSettings()).solve(start, goal, wall)
    assert again.success and cold.success
    assert again.dt.sum() == pytest.approx(cold.dt.sum(), rel=0.05)
    assert math.isfinite(again.clearance(wall))


def test_teb_reports_a_failure_rather_than_raising() -> None:
    band = TebPlanner().solve(
        np.array([0.0, 0.0, 0.0]), np.array([np.nan, 0.0, 0.0]), np.zeros((0, 2))
    )
    assert not band.success


@pytest.mark.parametrize("factor", [2, 3])
def test_a_coarsened_costmap_keeps_each_blocks_worst_cell(factor: int) -> None:
    costmap = inflate(FRAME, _walls((0.2, 1.2)), inscribed=0.35, decay=3.0)
    coarse = costmap.coarsened(factor)
    nx, ny = coarse.cost.shape
    blocks = (nx, factor, ny, factor)
    cost = costmap.cost[: nx * factor, : ny * factor].reshape(blocks).max(axis=(1, 3))
    distance = costmap.distance[: nx * factor, : ny * factor].reshape(blocks).min(axis=(1, 3))
    assert np.array_equal(coarse.cost, cost) and np.array_equal(coarse.distance, distance)
