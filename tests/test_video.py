"""``--video`` renders offscreen at 30 frames per simulated second."""

from __future__ import annotations

import json

import imageio_ffmpeg
import numpy as np

from ridempc.cli import main


def test_video_is_rendered(tmp_path, capsys) -> None:
    out = tmp_path / "video"
    code = main(["sim", "--robot", "cyberdog2", "--duration", "0.5", "--video", "--out", str(out)])
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    assert "video.mp4" in summary["files"]
    reader = imageio_ffmpeg.read_frames(str(out / "video.mp4"))
    meta = next(reader)
    width, height = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    assert len(frames) == 16  # t = 0, 1/30, ..., 0.5 s
    assert np.std(frames[-1]) > 5.0  # a picture, not a blank frame
