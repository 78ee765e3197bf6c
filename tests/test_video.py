"""``--video`` renders offscreen at 30 frames per simulated second; ``--snapshots`` a strip."""

from __future__ import annotations

import json

import imageio_ffmpeg
import numpy as np
import pytest

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


def test_snapshot_strip_is_written(tmp_path) -> None:
    import imageio.v2 as imageio

    out = tmp_path / "snap"
    args = ["sim", "--robot", "cyberdog2", "--duration", "0.5", "--snapshots", "3"]
    assert main([*args, "--no-plots", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert "snapshots.png" in summary["files"]
    image = imageio.imread(out / "snapshots.png")
    assert image.shape[1] > 2 * image.shape[0]  # three frames side by side
    assert np.std(image[..., :3]) > 5.0
    assert not list(out.glob(".*.tmp.png"))


def test_negative_snapshot_count_is_refused(tmp_path, capsys) -> None:
    out = tmp_path / "bad"
    with pytest.raises(SystemExit) as exited:  # argparse's error, one line
        main(["sim", "--snapshots", "-1", "--out", str(out)])
    assert exited.value.code == 2
    assert "--snapshots: -1 is out of range" in capsys.readouterr().err
    assert not out.exists()


def test_video_without_its_extra_is_refused_before_the_ride(tmp_path, capsys, monkeypatch) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "imageio_ffmpeg" else real(name, *a),
    )
    out = tmp_path / "video"
    code = main(["sim", "--robot", "cyberdog2", "--duration", "0.5", "--video", "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "'video' extra" in err and "pip install" in err
    assert not out.exists()
