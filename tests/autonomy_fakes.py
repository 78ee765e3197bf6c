"""Stand-ins for the navigator's sensor and rider in the autonomy tests."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from ridempc.autonomy.camera import CameraIntrinsics, DepthCameraSpec, pixel_rays
from ridempc.scenarios.scenario import Command


class BlindSensor:
    """A depth camera that delivers no frame: the map is the test's."""

    def __init__(self) -> None:
        self.spec = DepthCameraSpec()
        self.rays = pixel_rays(CameraIntrinsics.of(self.spec))

    def capture(self, t: float, data: object) -> None:
        pass

    def delivered(self, t: float) -> None:
        return None


class KinematicRider:
    """A unicycle whose speed and yaw rate follow the command with a 0.3 s lag."""

    def __init__(self) -> None:
        self.pose = np.zeros(3)
        self.speed = 0.0
        self.turn = 0.0

    def estimate(self) -> SimpleNamespace:
        yaw = self.pose[2]
        return SimpleNamespace(
            base_position=np.array([self.pose[0], self.pose[1], 1.0]),
            base_quaternion=np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]),
        )

    def step(self, command: Command, dt: float) -> None:
        self.speed += (command.velocity - self.speed) * dt / 0.3
        self.turn += (command.yaw_rate - self.turn) * dt / 0.3
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        self.pose += dt * np.array([self.speed * c, self.speed * s, self.turn])
