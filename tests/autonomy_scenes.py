"""Depth images rendered by formula (planes and boxes, ray by ray) for the autonomy tests."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.camera import CameraIntrinsics, DepthCameraSpec, camera_rotation, pixel_rays

Array = NDArray[np.float64]


def ground_depth(direction: Array, origin: Array, slope: float, step: tuple[float, float]) -> Array:
    """Ray parameter to the ground z = tan(slope) x (+ step height beyond x = step[0])."""
    normal = np.array([-math.tan(slope), 0.0, 1.0])
    t = -(origin @ normal) / np.minimum(direction @ normal, -1e-9)
    if step[1] != 0.0:
        beyond = origin[0] + t * direction[:, 0] > step[0]
        lifted = (step[1] - origin @ normal) / np.minimum(direction @ normal, -1e-9)
        # the raised part starts at x = step[0]: rays that cross the riser hit it
        riser = (step[0] - origin[0]) / np.where(
            np.abs(direction[:, 0]) > 1e-9, direction[:, 0], 1e-9
        )
        z_riser = origin[2] + riser * direction[:, 2] - math.tan(slope) * step[0]
        on_riser = beyond & (riser > 0) & (z_riser < step[1])
        t = np.where(beyond, np.where(on_riser, riser, lifted), t)
    return t


def box_depth(direction: Array, origin: Array, low: Array, high: Array) -> Array:
    """Ray parameter to an axis-aligned box (slab method), inf where missed."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (low - origin) / direction
        t2 = (high - origin) / direction
    near = np.nanmax(np.minimum(t1, t2), axis=1)
    far = np.nanmin(np.maximum(t1, t2), axis=1)
    return np.where((far >= near) & (near > 0.0), near, np.inf)


def render(
    position: Array,
    yaw: float,
    spec: DepthCameraSpec,
    boxes: list[tuple[Array, Array]] = (),  # type: ignore[assignment]
    slope: float = 0.0,
    step: tuple[float, float] = (0.0, 0.0),
) -> tuple[Array, Array, Array]:
    """A depth image [m] (0 beyond range) and the camera's rays and rotation."""
    intrinsics = CameraIntrinsics.of(spec)
    rays = pixel_rays(intrinsics)
    rotation = camera_rotation(yaw, math.radians(spec.tilt))
    direction = rays.reshape(-1, 3) @ rotation.T  # unit depth along the axis
    t = ground_depth(direction, position, slope, step)
    for low, high in boxes:
        t = np.minimum(t, box_depth(direction, position, low, high))
    t[(t < spec.min_range) | (t > spec.max_range) | ~np.isfinite(t)] = 0.0
    return t.reshape(rays.shape[:2]), rays, rotation
