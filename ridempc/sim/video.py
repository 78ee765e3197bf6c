"""Offscreen video of a run: frames rendered at 30 Hz of simulation time, written as mp4."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

__all__ = ["VideoRecorder", "require_video_writer", "tracking_camera"]


def require_video_writer() -> None:
    """Refuse ``--video`` up front when the ``video`` extra (the ffmpeg binary) is missing.

    Raises:
        ConfigError: imageio-ffmpeg is not installed; the message names the extra.
    """
    import importlib.util

    from ridempc.errors import ConfigError

    if importlib.util.find_spec("imageio_ffmpeg") is None:
        raise ConfigError(
            "--video needs the 'video' extra (the ffmpeg binary, about 170 MB), which is not "
            'installed: pip install "ridempc[video]" '
            '(from a checkout: pip install -e ".[video]")'
        )


def tracking_camera(track_body: int, distance: float) -> mujoco.MjvCamera:
    """A camera following ``track_body`` from ``distance`` [m], front-left and a little above."""
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    camera.trackbodyid = track_body
    camera.distance = distance
    camera.azimuth = 135.0
    camera.elevation = -15.0
    return camera


class VideoRecorder:
    """Renders frames from a camera tracking the robot's base and writes them to mp4.

    Frames are streamed to a temporary file that is renamed into place only when the
    video is complete.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        path: Path,
        track_body: int,
        fps: int = 30,
        distance: float = 3.0,
        width: int = 640,
        height: int = 480,
    ) -> None:
        import imageio.v2 as imageio

        self.path = Path(path)
        self._tmp = self.path.with_name(f".{self.path.name}.tmp.mp4")
        self._renderer = mujoco.Renderer(model, height=height, width=width)
        self._camera = tracking_camera(track_body, distance)
        self._writer = imageio.get_writer(self._tmp, fps=fps, macro_block_size=1)
        self.frames = 0
        self.last_frame: np.ndarray | None = None

    def __call__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self._renderer.update_scene(data, self._camera)
        frame = self._renderer.render()
        self._writer.append_data(frame)
        self.last_frame = frame
        self.frames += 1

    def close(self, keep: bool = True) -> None:
        """Finish the file and rename it into place (``keep`` and frames), else remove it."""
        try:
            self._writer.close()
            self._renderer.close()
            if keep and self.frames:
                self._tmp.replace(self.path)
        finally:
            self._tmp.unlink(missing_ok=True)
