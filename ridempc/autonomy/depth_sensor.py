"""The depth camera in the simulation: mounted on the rider, rendered or ray-cast.

:func:`add_depth_camera` adds the camera to the rider's base body in the scene's model
spec (the robot's file stays untouched). :class:`DepthSensor` then captures frames at its
rate, either rendered by MuJoCo offscreen (``render``: the depth buffer, EGL on a headless
machine) or ray-cast with ``mj_multiRay`` (``raycast``: deterministic, no GPU), adds the
stereo noise and delivers each frame after the camera's latency. Like the other sensors,
it reads the simulator; what it delivers (depth images and their capture times) is all
the planner gets from it.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.camera import CameraIntrinsics, DepthCameraSpec, camera_rotation, pixel_rays
from ridempc.errors import ConfigError

__all__ = ["CAMERA_NAME", "DepthFrame", "DepthSensor", "add_depth_camera", "mount_pose"]

Array = NDArray[np.float64]

CAMERA_NAME = "depth_camera"
MODES = ("raycast", "render")


def mount_pose(spec: DepthCameraSpec) -> tuple[Array, Array]:
    """Camera position [m] and camera-to-base rotation in the base body's frame."""
    return np.asarray(spec.mount, dtype=float), camera_rotation(0.0, math.radians(spec.tilt))


def add_depth_camera(model_spec: mujoco.MjSpec, body: str, spec: DepthCameraSpec) -> None:
    """Add the camera to ``body`` of a model spec, before it is compiled."""
    parent = model_spec.body(body)
    if parent is None:
        raise ConfigError(f"depth camera: the model has no body '{body}'")
    position, rotation = mount_pose(spec)
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, rotation.reshape(-1))
    parent.add_camera(name=CAMERA_NAME, pos=position.tolist(), quat=quat.tolist(), fovy=spec.fovy)


@dataclass(frozen=True)
class DepthFrame:
    """One delivered frame.

    Attributes:
        time: Capture time [s].
        depth: Depth along the optical axis [m], 0 where nothing was seen, shape (h, w).
    """

    time: float
    depth: Array


class DepthSensor:
    """Captures and delivers depth frames.

    Args:
        model: The compiled scene (with :func:`add_depth_camera`'s camera).
        spec: The camera.
        rng: Noise source.
        mode: ``raycast`` or ``render``.
    """

    def __init__(
        self, model: mujoco.MjModel, spec: DepthCameraSpec, rng: np.random.Generator, mode: str
    ) -> None:
        if mode not in MODES:
            raise ConfigError(f"camera mode '{mode}': allowed: {', '.join(MODES)}")
        self.spec = spec
        self.intrinsics = CameraIntrinsics.of(spec)
        self.rays = pixel_rays(self.intrinsics)
        self._model = model
        self._camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, CAMERA_NAME)
        if self._camera < 0:
            raise ConfigError("depth camera: the scene has no camera (add_depth_camera)")
        self._body = int(model.cam_bodyid[self._camera])
        self._rng = rng
        self._pending: deque[DepthFrame] = deque()
        self._renderer: mujoco.Renderer | None = None
        if mode == "render":
            self._renderer = mujoco.Renderer(model, spec.height, spec.width)
            self._renderer.enable_depth_rendering()
        norms = np.linalg.norm(self.rays, axis=-1)
        self._directions = (self.rays / norms[..., None]).reshape(-1, 3)
        self._norms = norms.reshape(-1)

    def capture(self, t: float, data: mujoco.MjData) -> None:
        """Take a frame now; it is delivered ``spec.latency`` later."""
        if self._renderer is not None:
            self._renderer.update_scene(data, camera=self._camera)
            depth = np.array(self._renderer.render(), dtype=float)
        else:
            depth = self._raycast(data)
        depth[(depth < self.spec.min_range) | (depth > self.spec.max_range)] = 0.0
        seen = depth > 0.0
        depth[seen] += self.spec.noise * depth[seen] ** 2 * self._rng.standard_normal(seen.sum())
        self._pending.append(DepthFrame(t, depth))

    def _raycast(self, data: mujoco.MjData) -> Array:
        rotation = data.cam_xmat[self._camera].reshape(3, 3)
        origin = data.cam_xpos[self._camera].copy()
        vectors = (self._directions @ rotation.T).reshape(-1)
        n = len(self._directions)
        geoms = np.empty(n, dtype=np.int32)
        distance = np.empty(n)
        cutoff = self.spec.max_range * float(self._norms.max())
        mujoco.mj_multiRay(  # the camera's own body (its housing, the pelvis) excluded
            self._model,
            data,
            origin,
            vectors,
            None,
            1,
            self._body,
            geoms,
            distance,
            None,
            n,
            cutoff,
        )
        depth = np.where(distance >= 0.0, distance / self._norms, 0.0)
        return depth.reshape(self.spec.height, self.spec.width)

    def delivered(self, t: float) -> DepthFrame | None:
        """The newest frame delivered by time ``t`` [s] (older ones are dropped), or None."""
        latest = None
        while self._pending and self._pending[0].time + self.spec.latency <= t + 1e-9:
            latest = self._pending.popleft()
        return latest

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
