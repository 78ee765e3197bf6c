"""Perception on depth images rendered by formula: voxels, ground, occupancy, scan."""

from __future__ import annotations

import math

import numpy as np
import pytest
from autonomy_scenes import render

from ridempc.autonomy.camera import CameraIntrinsics, DepthCameraSpec, pixel_rays, to_points
from ridempc.autonomy.course import Box, resolve_course
from ridempc.autonomy.evaluation import CellScores, score_cells
from ridempc.autonomy.ground import segment_ground
from ridempc.autonomy.incline import incline_ahead
from ridempc.autonomy.navigator import NavigatorSettings
from ridempc.autonomy.occupancy import GridFrame, OccupancyGrid
from ridempc.autonomy.perception import FUSE_RANGE, Perception
from ridempc.autonomy.scan import pseudo_scan
from ridempc.autonomy.voxels import voxel_filter

SPEC = DepthCameraSpec()
HEIGHT = 1.2  # [m] the camera over the ground, as on Cassie's pelvis on the shoes


def _noisy(depth: np.ndarray, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    seen = depth > 0
    depth = depth.copy()
    depth[seen] += SPEC.noise * depth[seen] ** 2 * rng.standard_normal(seen.sum())
    return depth


def _box(x: float, y: float, size: tuple[float, float, float], slope: float = 0.0):
    """A box standing on the slope z = tan(slope) x: (low, high) corners and its Box."""
    base = math.tan(slope) * (x - 0.5 * size[0]) - 0.05  # sunk into the slope's low side
    low = np.array([x - size[0] / 2, y - size[1] / 2, base])
    high = np.array(
        [x + size[0] / 2, y + size[1] / 2, math.tan(slope) * (x + size[0] / 2) + size[2]]
    )
    return (low, high), Box(center=(x, y), size=size)


def test_voxel_filter_keeps_one_centroid_per_voxel() -> None:
    rng = np.random.default_rng(0)
    points = rng.uniform([0, 0, 0], [0.05, 0.05, 0.1], size=(50, 3))
    points = np.vstack([points, points + [0.05, 0.0, 0.0]])
    voxels = voxel_filter(points)
    assert voxels.shape == (2, 3)
    assert np.allclose(np.sort(voxels[:, 0]), [points[:50, 0].mean(), points[:50, 0].mean() + 0.05])


@pytest.mark.parametrize("slope_deg", [0.0, 7.0, 13.0])
def test_ground_holds_on_slopes_and_finds_the_box(slope_deg: float) -> None:
    slope = math.radians(slope_deg)
    corners, _ = _box(2.0, 0.0, (0.4, 0.4, 0.3), slope)
    position = np.array([0.0, 0.0, HEIGHT])
    depth, rays, rotation = render(position, 0.0, SPEC, [corners], slope=slope)
    split = segment_ground(voxel_filter(to_points(_noisy(depth, 1), rays, rotation, position)))
    on_box = (np.abs(split.obstacles[:, 0] - 2.0) < 0.25) & (np.abs(split.obstacles[:, 1]) < 0.25)
    assert on_box.all()  # no false obstacle on the slope
    assert on_box.sum() > 20
    ground_on_box = (np.abs(split.ground[:, 0] - 2.0) < 0.18) & (np.abs(split.ground[:, 1]) < 0.18)
    assert ground_on_box.sum() <= 0.05 * on_box.sum()


def test_a_low_step_is_ground_and_a_high_one_is_not() -> None:
    position = np.array([0.0, 0.0, HEIGHT])
    for rise, obstacle in ((0.05, False), (0.2, True)):
        depth, rays, rotation = render(position, 0.0, SPEC, step=(2.0, rise))
        split = segment_ground(voxel_filter(to_points(depth, rays, rotation, position)))
        assert (len(split.obstacles) > 10) == obstacle
        if obstacle:  # the riser and the top's edge (higher than the slope limit climbs)
            assert np.all((split.obstacles[:, 0] > 1.95) & (split.obstacles[:, 0] < 2.4))


def _map(slope: float, boxes: list, poses: list[tuple[float, float, float]]) -> OccupancyGrid:
    grid = OccupancyGrid(GridFrame((-1.0, -3.0), 0.05, (140, 120)))
    for k, (x, y, yaw) in enumerate(poses):
        position = np.array([x, y, HEIGHT + math.tan(slope) * x])
        depth, rays, rotation = render(position, yaw, SPEC, [c for c, _ in boxes], slope=slope)
        points = voxel_filter(to_points(_noisy(depth, k), rays, rotation, position))
        split = segment_ground(points)
        grid.update(position, split.ground, split.obstacles)
    return grid


@pytest.mark.parametrize("slope_deg", [0.0, 7.0, 13.0])
def test_occupancy_precision_and_recall_within_3m(slope_deg: float) -> None:
    slope = math.radians(slope_deg)
    boxes = [_box(2.2, 0.6, (0.4, 0.4, 0.4), slope), _box(2.8, -0.7, (0.3, 0.6, 0.25), slope)]
    poses = [(0.0, 0.0, 0.0), (0.3, 0.0, 0.1), (0.6, 0.0, -0.1), (0.9, 0.0, 0.0)]
    grid = _map(slope, boxes, poses)
    path = np.array([[x, y] for x, y, _ in poses])
    scores = score_cells(
        grid.frame, grid.occupied(), grid.observed, [b for _, b in boxes], path, radius=3.0
    )
    assert scores.precision >= 0.95
    assert scores.recall >= 0.95
    assert scores.false_share < 0.01


@pytest.mark.parametrize("slope_deg", [0.0, 7.0, 13.0])
def test_the_incline_ahead_is_measured_on_the_maps_ground(slope_deg: float) -> None:
    poses = [(0.0, 0.0, 0.0), (0.3, 0.0, 0.1), (0.6, 0.0, -0.1)]
    grid = _map(math.radians(slope_deg), [], poses)
    settings = NavigatorSettings()
    rider = np.array([1.5, 0.0])  # on ground the poses saw ahead of them
    incline = incline_ahead(
        grid.frame, grid.ground, rider, 0.0, settings.incline_reach, settings.incline_behind
    )
    assert math.degrees(incline) == pytest.approx(slope_deg, abs=1.5)
    assert (incline >= settings.incline_hold) == (slope_deg > 0.0)
    across = incline_ahead(grid.frame, grid.ground, rider, 0.5 * math.pi, 1.0, 0.3)
    assert across < settings.incline_hold  # the slope rises along x, level across it


def test_a_low_box_is_no_incline() -> None:
    poses = [(0.0, 0.0, 0.0), (0.3, 0.0, 0.1), (0.6, 0.0, -0.1), (0.9, 0.0, 0.0)]
    grid = _map(0.0, [_box(2.2, 0.0, (0.6, 0.2, 0.1))], poses)  # the straddle course's
    settings = NavigatorSettings()
    incline = incline_ahead(
        grid.frame, grid.ground, np.array([1.5, 0.0]), 0.0, 1.0, 0.3, grid.occupied()
    )
    assert incline < settings.incline_hold


# the terrain issue's steps, from the Hovershoes library: 1.71 wheel radii (0.076 m), and the
# stairs' 0.79 and 0.93 (0.035, 0.041 m); down as ridden, and up
@pytest.mark.parametrize("rise", [-0.076, -0.041, -0.035, 0.035, 0.041, 0.076])
def test_a_rideable_step_leaves_under_1_percent_false_cells(rise: float) -> None:
    grid = OccupancyGrid(GridFrame((-1.0, -3.0), 0.05, (140, 120)))
    poses = [(0.3 * k, 0.0, 0.1 * (-1) ** k) for k in range(6)]  # up to 0.5 m short of it
    for k, (x, y, yaw) in enumerate(poses):
        position = np.array([x, y, HEIGHT])
        depth, rays, rotation = render(position, yaw, SPEC, step=(2.0, rise))
        split = segment_ground(voxel_filter(to_points(_noisy(depth, k), rays, rotation, position)))
        grid.update(position, split.ground, split.obstacles)
    path = np.array([[x, y] for x, y, _ in poses])
    scores = score_cells(grid.frame, grid.occupied(), grid.observed, [], path, radius=3.0)
    assert scores.false_share < 0.01


def test_free_rays_clear_a_stale_obstacle() -> None:
    grid = _map(0.0, [], [(0.0, 0.0, 0.0)])
    cell = grid.frame.cells(np.array([[2.0, 0.0]]))[0][0]
    grid.log_odds[cell[0], cell[1]] = 3.5  # a box that was there
    for _ in range(12):
        position = np.array([0.0, 0.0, HEIGHT])
        depth, rays, rotation = render(position, 0.0, SPEC)
        split = segment_ground(voxel_filter(to_points(depth, rays, rotation, position)))
        grid.update(position, split.ground, split.obstacles)
    assert not grid.occupied()[cell[0], cell[1]]


def test_pseudo_scan_ranges_to_the_box_face() -> None:
    corners, _ = _box(2.0, 0.0, (0.4, 0.4, 0.4))
    position = np.array([0.0, 0.0, HEIGHT])
    depth, rays, rotation = render(position, 0.0, SPEC, [corners])
    split = segment_ground(voxel_filter(to_points(depth, rays, rotation, position)))
    scan = pseudo_scan(split.obstacles, position[:2], 0.0, math.radians(87.0))
    ahead = np.abs(scan.bearings) < 0.03
    assert scan.ranges[ahead].min() == pytest.approx(1.8, abs=0.05)  # the front face
    assert (scan.ranges[ahead] <= 2.25).all()  # a beam missing the face ends on the top
    assert np.isinf(scan.ranges[np.abs(scan.bearings) > 0.3]).all()


def _slalom_scores(fuse_range: float) -> CellScores:
    """The slalom's walls and gates mapped from 100 noisy frames weaving through its gates."""
    course = resolve_course("slalom")
    boxes = [
        (
            np.array([b.center[0] - b.size[0] / 2, b.center[1] - b.size[1] / 2, -0.05]),
            np.array([b.center[0] + b.size[0] / 2, b.center[1] + b.size[1] / 2, b.size[2]]),
        )
        for b in course.obstacles
    ]
    grid = OccupancyGrid(GridFrame((-1.0, -3.0), 0.05, (240, 120)))
    perception = Perception(grid, pixel_rays(CameraIntrinsics.of(SPEC)), 1.0, 0.45, fuse_range)
    x = np.linspace(0.0, 10.0, 100)
    y = 0.75 * np.sin(math.pi * (x - 1.0) / 3.0)
    yaw = np.arctan(0.75 * math.pi / 3.0 * np.cos(math.pi * (x - 1.0) / 3.0))
    for k in range(len(x)):
        position = np.array([x[k], y[k], HEIGHT])
        depth, _, rotation = render(position, yaw[k], SPEC, boxes)
        perception.update(_noisy(depth, k), rotation, position, position, yaw[k])
    return score_cells(
        grid.frame, grid.occupied(), grid.observed, course.obstacles, np.column_stack([x, y])
    )


def test_far_depths_are_not_fused_so_the_slaloms_far_edges_stay_clean() -> None:
    # the tops of walls and gates seen from afar read cells behind their far faces, where
    # the camera never sees the ground to clear them
    near, far = _slalom_scores(FUSE_RANGE), _slalom_scores(SPEC.max_range)
    assert near.recall >= 0.95 and near.precision >= 0.95 and near.false_share < 0.01
    assert near.false_share < 0.8 * far.false_share
