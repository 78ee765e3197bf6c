"""MuJoCo's interactive viewer, kept in step with simulation time (needs a display)."""

from __future__ import annotations

import time

import mujoco

__all__ = ["LiveViewer"]


class LiveViewer:
    """A passive viewer synced at each frame and paced to real time."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        import mujoco.viewer

        self._handle = mujoco.viewer.launch_passive(model, data)
        self._wall0 = time.perf_counter()
        self._sim0 = float(data.time)

    def __call__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        ahead = (data.time - self._sim0) - (time.perf_counter() - self._wall0)
        if ahead > 0.0:
            time.sleep(ahead)
        if self._handle.is_running():
            self._handle.sync()

    def close(self) -> None:
        self._handle.close()
