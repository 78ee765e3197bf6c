"""The wave pattern chosen by the planner: finding a straddle, its lane, a kinematic pass."""

from __future__ import annotations

import numpy as np
import pytest
from autonomy_fakes import BlindSensor, KinematicRider

from ridempc.autonomy.costmap import inflate
from ridempc.autonomy.course import Box, resolve_course
from ridempc.autonomy.dijkstra import plan
from ridempc.autonomy.evaluation import rasterise
from ridempc.autonomy.navigate import map_frame
from ridempc.autonomy.navigator import Navigator
from ridempc.autonomy.occupancy import GridFrame, OccupancyGrid
from ridempc.autonomy.straddle import (
    StraddleSettings,
    find_straddles,
    lane_walls,
    onto_axes,
    straddle_lethal,
)

FRAME = GridFrame((0.0, -2.0), 0.05, (120, 80))  # 6 m x 4 m
SETTINGS = StraddleSettings()
RIDER = np.array([0.5, 0.0])


def _grid(boxes: list[Box], height: float) -> tuple[np.ndarray, np.ndarray]:
    occupied = rasterise(FRAME, boxes)
    return occupied, np.where(occupied, height, -np.inf)


def test_a_low_narrow_box_is_a_straddle_along_its_length() -> None:
    box = Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.1))
    (straddle,) = find_straddles(FRAME, *_grid([box], 0.12), SETTINGS, RIDER)
    assert abs(straddle.axis[0]) == pytest.approx(1.0, abs=1e-6)
    assert 2.0 * straddle.half_width == pytest.approx(0.2, abs=0.051)
    assert 2.0 * straddle.half_length == pytest.approx(0.6, abs=0.051)
    assert straddle.center == pytest.approx([3.0, 0.0], abs=0.03)


@pytest.mark.parametrize(
    ("size", "height"),
    [((0.6, 0.2, 0.5), 0.5), ((0.6, 0.5, 0.1), 0.12)],
    ids=["too-tall", "too-wide"],
)
def test_a_tall_or_wide_box_is_ridden_round(
    size: tuple[float, float, float], height: float
) -> None:
    box = Box(center=(3.0, 0.0), size=size)
    assert find_straddles(FRAME, *_grid([box], height), SETTINGS, RIDER) == ()


def test_an_occupied_cell_of_unknown_height_is_not_straddled() -> None:
    occupied, _ = _grid([Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.1))], 0.12)
    assert find_straddles(FRAME, occupied, np.full(FRAME.shape, -np.inf), SETTINGS, RIDER) == ()


def test_a_speckle_of_low_cells_is_no_straddle() -> None:
    occupied, height = _grid([Box(center=(3.01, 0.01), size=(0.04, 0.04, 0.1))], 0.1)
    assert 0 < occupied.sum() < SETTINGS.min_cells
    assert find_straddles(FRAME, occupied, height, SETTINGS, RIDER) == ()


def test_a_box_seen_by_its_front_face_is_ridden_along_the_approach() -> None:
    face = Box(center=(3.0, 0.0), size=(0.05, 0.25, 0.1))  # narrow both ways
    (straddle,) = find_straddles(FRAME, *_grid([face], 0.12), SETTINGS, RIDER)
    assert abs(straddle.axis[0]) == pytest.approx(1.0, abs=1e-6)


def test_the_global_path_crosses_a_straddle_on_its_axis() -> None:
    box = Box(center=(3.0, 0.02), size=(0.6, 0.2, 0.1))
    occupied, height = _grid([box], 0.12)
    straddles = find_straddles(FRAME, occupied, height, SETTINGS, RIDER)
    costmap = inflate(FRAME, occupied & ~straddles[0].cells, 0.35, 3.0)
    lane = SETTINGS.lane + 2 * FRAME.resolution
    lethal = straddle_lethal(FRAME, straddles, 0.35, lane)
    x, y = FRAME.centers()
    assert lethal[(np.abs(x - 3.0) < 0.2) & (np.abs(y - 0.3) < 0.03)].all()  # beside it
    assert not lethal[(np.abs(x - 3.0) < 0.2) & (np.abs(y - 0.02) < 0.03)].any()  # on it
    costmap.cost[lethal] = np.inf
    path = onto_axes(
        plan(costmap.coarsened(2), np.array([0.5, 0.0]), np.array([5.5, 0.0])),
        straddles,
        0.35,
        lane,
    )
    over = np.abs(path[:, 0] - 3.0) <= 0.3
    assert over.any() and np.abs(path[over, 1] - straddles[0].center[1]).max() < 1e-9
    walls = lane_walls(straddles[0], 0.5, SETTINGS.lane)
    assert np.abs(np.abs(walls[:, 1] - straddles[0].center[1]) - 0.56).max() < 1e-6


def test_a_kinematic_rider_straddles_the_low_box_with_its_feet_spread() -> None:
    course = resolve_course("straddle").in_start_frame()
    (box,) = course.obstacles
    frame = map_frame(course)
    grid = OccupancyGrid(frame)
    cells = rasterise(frame, course.obstacles)
    grid.log_odds[cells] = 3.0  # the map the camera would build, and the heights it measures
    grid.height[cells] = 0.16
    rider = KinematicRider()
    hz = 100
    navigator = Navigator(np.asarray(course.goal), grid, BlindSensor(), rider, hz)  # type: ignore[arg-type]
    over: list[tuple[float, float]] = []  # (lateral place [m], feet's offset [m]) over the box
    for tick in range(round(course.duration * hz)):
        t = tick / hz
        navigator(t, None, None)
        command = navigator.command_at(t)
        rider.step(command, 1.0 / hz)
        if box.contains(rider.pose[:2])[0]:
            over.append((float(rider.pose[1]), command.lateral_offset))
    assert navigator.arrived_at is not None
    assert np.hypot(*(rider.pose[:2] - course.goal)) < course.goal_tolerance
    assert len(navigator.straddles) == 1 and over
    lateral, spread = np.array(over).T
    assert np.abs(lateral - box.center[1]).max() < SETTINGS.lane + 0.02
    assert spread.min() == pytest.approx(SETTINGS.spread)
    assert navigator.command_at(course.duration).lateral_offset == 0.0  # closed at the goal


def test_a_straddles_cells_seen_between_replans_are_not_the_bands_obstacles() -> None:
    course = resolve_course("straddle").in_start_frame()
    frame = map_frame(course)
    grid = OccupancyGrid(frame)
    cells = rasterise(frame, course.obstacles)
    grid.log_odds[cells] = 3.0
    grid.height[cells] = 0.16
    navigator = Navigator(np.asarray(course.goal), grid, BlindSensor(), KinematicRider(), 100)  # type: ignore[arg-type]
    rider = np.array([2.0, 0.0])
    assert navigator._replan(rider, 0.0) and len(navigator.straddles) == 1
    (box,) = course.obstacles
    grown = frame.cells(np.array([[box.center[0] + 0.5 * box.size[0] + 0.03, 0.0]]))[0][0]
    grid.log_odds[grown[0], grown[1]] = 3.0  # the box's far end, seen since the replan
    grid.height[grown[0], grown[1]] = 0.16
    points = navigator._nearby_obstacles(rider)
    near_box = box.contains(points, margin=0.1)
    assert not near_box.any()  # only the lane's walls, 0.56 m either side
