"""A strip of still frames of a run, evenly spaced in simulation time, saved as one PNG.

Cheaper than a video (a handful of renders instead of 30 a second) and the picture a report
shows: each frame is rendered from a camera tracking the rider's base, as in
:func:`~ridempc.sim.video.tracking_camera`, and labelled with its time. The PNG is written
to a temporary name and renamed into place, so a failed run never leaves half an image.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from ridempc.io import atomic_savefig
from ridempc.sim.video import tracking_camera

__all__ = ["SnapshotStrip"]


class SnapshotStrip:
    """Renders ``count`` frames at :math:`t_k = k\\,T/(\\mathrm{count}-1)` [s] and tiles them.

    Args:
        model: The compiled scene.
        path: Where the PNG goes.
        track_body: Body the camera follows (the rider's base).
        duration: The run's duration :math:`T` [s].
        count: Number of frames (at least 1; one frame is taken at the end).
        distance: Camera distance [m].
        width: Width of each frame [px].
        height: Height of each frame [px].
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        path: Path,
        track_body: int,
        duration: float,
        count: int = 4,
        distance: float = 3.0,
        width: int = 480,
        height: int = 360,
    ) -> None:
        if count < 1:
            raise ValueError(f"snapshot count must be at least 1, got {count}")
        self.path = Path(path)
        self.times = np.linspace(0.0, duration, count) if count > 1 else np.array([duration])
        self._renderer = mujoco.Renderer(model, height=height, width=width)
        self._camera = tracking_camera(track_body, distance)
        self.frames: list[tuple[float, np.ndarray]] = []

    def __call__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        taken = len(self.frames)
        if taken < len(self.times) and data.time >= self.times[taken] - 1e-9:
            self.frames.append((float(data.time), self._render(data)))

    def _render(self, data: mujoco.MjData) -> np.ndarray:
        self._renderer.update_scene(data, self._camera)
        return self._renderer.render().copy()

    def discard(self) -> None:
        """Release the renderer and write nothing (the run did not finish)."""
        self.frames.clear()
        self._renderer.close()

    def close(self, data: mujoco.MjData | None = None) -> None:
        """Take the missing last frame from ``data`` (a run that ended early shows its end)
        and write the PNG; nothing is written without frames."""
        if data is not None and len(self.frames) < len(self.times):
            self.frames.append((float(data.time), self._render(data)))
        self._renderer.close()
        if not self.frames:
            return
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, len(self.frames), figsize=(3.2 * len(self.frames), 2.9))
        for ax, (time, frame) in zip(np.atleast_1d(axes), self.frames, strict=True):
            ax.imshow(frame)
            ax.set_title(f"t = {time:.1f} s", fontsize=10)
            ax.axis("off")
        fig.tight_layout()
        try:
            atomic_savefig(fig, self.path, dpi=100)
        finally:
            plt.close(fig)
