"""A RealSense D435-class depth camera: its intrinsics, mount, noise and back-projection.

The camera follows MuJoCo's convention: it looks along its frame's :math:`-z`, with
:math:`x` to the right of the image and :math:`y` up. A depth image holds, per pixel, the
distance along the optical axis [m] (what MuJoCo's depth buffer and a RealSense give), 0
where nothing was seen within range. Stereo depth error grows with the square of the
distance,

.. math:: \\sigma_z = k \\, z^2, \\qquad k = \\frac{\\epsilon_{subpixel}}{f \\, b},

with :math:`f` the focal length [px] and :math:`b` the stereo baseline [m]: the D435's
0.08 px subpixel error, 50 mm baseline and 424 px focal length at 848 px give
:math:`k \\approx 0.004` [1/m].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from ridempc.units import CheckedModel, Real

__all__ = ["CameraIntrinsics", "DepthCameraSpec", "camera_rotation", "pixel_rays", "to_points"]

Array = NDArray[np.float64]


class DepthCameraSpec(CheckedModel):
    """A depth camera and where it sits on the rider.

    Attributes:
        width: Image width [px]; a quarter of the D435's 848 keeps rendering cheap.
        height: Image height [px].
        fovy: Vertical field of view [deg] (the D435's 58; the horizontal one, 87-89, follows
            from the aspect ratio with square pixels).
        rate_hz: Frame rate [Hz] (the D435 gives up to 90; the planner runs at 10).
        latency: Time from exposure to delivery [s].
        noise: Depth noise coefficient :math:`k` of :math:`\\sigma_z = k z^2` [1/m].
        min_range: Closest depth measured [m] (the D435's minimum at 848 px).
        max_range: Farthest depth kept [m]; stereo error beyond it exceeds a voxel.
        tilt: Pitch of the optical axis below the horizontal [deg].
        mount: Camera position in the base body's frame [m].
    """

    width: int = Field(default=212, ge=8, le=848)
    height: int = Field(default=120, ge=8, le=480)
    fovy: Real = Field(default=58.0, gt=10.0, lt=120.0)
    rate_hz: Real = Field(default=15.0, gt=0.0, le=90.0)
    latency: Real = Field(default=0.05, ge=0.0, le=0.5)
    noise: Real = Field(default=0.004, ge=0.0, le=0.1)
    min_range: Real = Field(default=0.2, gt=0.0, le=2.0)
    max_range: Real = Field(default=4.0, gt=0.5, le=10.0)
    tilt: Real = Field(default=35.0, ge=0.0, le=90.0)
    mount: tuple[Real, Real, Real] = (0.12, 0.0, 0.1)


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics with square pixels (MuJoCo renders so)."""

    width: int
    height: int
    focal: float  # [px]

    @classmethod
    def of(cls, spec: DepthCameraSpec) -> CameraIntrinsics:
        focal = 0.5 * spec.height / math.tan(math.radians(spec.fovy) / 2.0)
        return cls(spec.width, spec.height, focal)

    @property
    def fovx(self) -> float:
        """Horizontal field of view [rad]."""
        return 2.0 * math.atan(0.5 * self.width / self.focal)


def pixel_rays(intrinsics: CameraIntrinsics) -> Array:
    """Per pixel, the camera-frame direction with unit depth: (x, y, -1), shape (h, w, 3)."""
    u = (np.arange(intrinsics.width) + 0.5 - 0.5 * intrinsics.width) / intrinsics.focal
    v = (0.5 * intrinsics.height - np.arange(intrinsics.height) - 0.5) / intrinsics.focal
    rays = np.empty((intrinsics.height, intrinsics.width, 3))
    rays[..., 0] = u[None, :]
    rays[..., 1] = v[:, None]
    rays[..., 2] = -1.0
    return rays


def camera_rotation(yaw: float, tilt: float) -> Array:
    """Camera-to-world rotation of a camera looking along heading ``yaw`` [rad], pitched
    ``tilt`` [rad] below the horizontal, image rows horizontal."""
    forward = np.array(
        [math.cos(tilt) * math.cos(yaw), math.cos(tilt) * math.sin(yaw), -math.sin(tilt)]
    )
    right = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
    up = np.cross(right, forward)
    return np.column_stack([right, up, -forward])


def to_points(depth: Array, rays: Array, rotation: Array, position: Array) -> Array:
    """World points of the valid pixels of a depth image [m], shape (n, 3).

    Args:
        depth: Depth along the optical axis [m], 0 where nothing was seen.
        rays: :func:`pixel_rays` of the camera.
        rotation: Camera-to-world rotation.
        position: Camera position in the world [m].
    """
    valid = depth > 0.0
    local = rays[valid] * depth[valid][:, None]
    return local @ rotation.T + position
