"""The command as a user meets it: names, bad input, exit codes, the output folder."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ridempc.cli import main
from ridempc.controllers import registry
from tests.helpers import LimpController, NanController


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        code = main(list(argv))
    except SystemExit as exc:  # argparse's errors: one line, exit 2
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_list_names_everything(capsys) -> None:
    code, out, _ = _run(capsys, "list")
    assert code == 0
    for word in ("cassie", "cyberdog2", "none", "stand", "stand-still", "push"):
        assert word in out


@pytest.mark.parametrize(
    ("option", "value", "valid"),
    [
        ("--robot", "atlas", "cyberdog2"),
        ("--board", "surfboard", "none"),
        ("--controller", "magic", "stand"),
        ("--scenario", "moonwalk", "stand-still"),
    ],
)
def test_unknown_names_exit_2_with_one_line(capsys, tmp_path: Path, option, value, valid) -> None:
    args = {
        "--robot": "cyberdog2",
        "--board": "none",
        "--controller": "stand",
        "--scenario": "stand-still",
    }
    args[option] = value
    argv = ["sim", *[x for kv in args.items() for x in kv], "--out", str(tmp_path / "o")]
    code, _, err = _run(capsys, *argv)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1
    assert value in lines[0] and valid in lines[0]
    assert not (tmp_path / "o" / "summary.json").exists()


def test_malformed_scenario_file_exits_2_naming_the_field(capsys, tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\nduration = "long"\n')
    code, _, err = _run(
        capsys, "sim", "--robot", "cyberdog2", "--scenario", str(bad), "--out", str(tmp_path / "o")
    )
    assert code == 2
    assert "duration" in err and len(err.strip().splitlines()) == 1


def test_a_ride_writes_its_results(capsys, tmp_path: Path) -> None:
    out = tmp_path / "ride"
    code, stdout, _ = _run(
        capsys, "sim", "--robot", "cyberdog2", "--duration", "1", "--out", str(out)
    )
    assert code == 0, stdout
    summary = json.loads((out / "summary.json").read_text())
    for key in (
        "robot",
        "board",
        "controller",
        "seed",
        "sim_time_s",
        "wall_time_s",
        "fell",
        "fall_time_s",
        "status",
        "velocity_rmse",
        "yaw_rate_rmse",
    ):
        assert key in summary
    assert summary["status"] == "ok" and summary["fell"] is False
    assert summary["sim_time_s"] == pytest.approx(1.0)
    assert (out / "log.npz").exists() and (out / "plots.png").exists()
    assert not list(out.glob(".*tmp*"))


def test_a_fall_is_recorded(capsys, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setitem(registry.CONTROLLERS, "limp", LimpController)
    out = tmp_path / "fall"
    code, _, _ = _run(
        capsys,
        "sim",
        "--robot",
        "cyberdog2",
        "--controller",
        "limp",
        "--duration",
        "3",
        "--out",
        str(out),
    )
    summary = json.loads((out / "summary.json").read_text())
    assert code == 0
    assert summary["fell"] is True and summary["status"] == "fell"
    assert 0.0 < summary["fall_time_s"] < 3.0
    assert summary["sim_time_s"] == pytest.approx(summary["fall_time_s"])


def test_a_diverging_run_fails_non_zero(capsys, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setitem(registry.CONTROLLERS, "nan", NanController)
    out = tmp_path / "nan"
    code, stdout, _ = _run(
        capsys,
        "sim",
        "--robot",
        "cyberdog2",
        "--controller",
        "nan",
        "--duration",
        "2",
        "--out",
        str(out),
    )
    summary = json.loads((out / "summary.json").read_text())
    assert code == 1
    assert summary["status"] == "failed" and "non-finite" in summary["error"]
    assert summary["sim_time_s"] == pytest.approx(0.5, abs=0.01)


def test_a_stale_summary_is_removed_before_a_run(capsys, tmp_path: Path, monkeypatch) -> None:
    out = tmp_path / "again"
    out.mkdir()
    (out / "summary.json").write_text('{"status": "ok"}')

    class Interrupted(LimpController):
        def update(self, sensors, command):
            if sensors.time > 0.1:
                raise KeyboardInterrupt
            return super().update(sensors, command)

    monkeypatch.setitem(registry.CONTROLLERS, "interrupted", Interrupted)
    code, _, err = _run(
        capsys, "sim", "--robot", "cyberdog2", "--controller", "interrupted", "--out", str(out)
    )
    assert code == 130 and "interrupted" in err
    assert not (out / "summary.json").exists()


def test_viewer_without_display_says_so(capsys, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    code, _, err = _run(
        capsys,
        "sim",
        "--robot",
        "cyberdog2",
        "--duration",
        "0.2",
        "--viewer",
        "--out",
        str(tmp_path / "v"),
    )
    assert code == 0
    assert "needs a display" in err


def test_board_identify_failure_writes_nothing(capsys, tmp_path: Path, monkeypatch) -> None:
    from ridempc.boards import board as board_module
    from ridempc.boards.identification import IdentificationFailed

    def fail(board):
        raise IdentificationFailed(f"{board.name}: roll fit did not converge")

    real_kind = board_module.Board.kind.fget

    def kind(self):
        return real_kind(self)._replace(identify=fail)

    monkeypatch.setattr(board_module.Board, "kind", property(kind))
    target = tmp_path / "id.json"
    code, _, err = _run(capsys, "board", "identify", "--board", "skateboard", "--json", str(target))
    assert code == 1
    assert "did not converge" in err and len(err.strip().splitlines()) == 1
    assert not target.exists()


def test_board_identify_unknown_board_exits_2(capsys) -> None:
    code, _, err = _run(capsys, "board", "identify", "--board", "surfboard")
    assert code == 2 and "surfboard" in err and "segway" in err
