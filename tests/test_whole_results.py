"""Whole results only: an ``--out`` folder never mixes two runs, a failed write leaves no
temporary file, and ``compare`` checks every controller and the scenario before it rides.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib
import pytest

from ridempc.cli import main
from ridempc.controllers import registry
from ridempc.io import atomic_savefig, atomic_write
from ridempc.results import COMPARISON_FILES, RUN_FILES
from tests.helpers import LimpController

matplotlib.use("Agg")

SIM = ["sim", "--robot", "cyberdog2", "--duration", "0.2", "--no-plots"]
COMPARE = ["compare", "--robot", "cyberdog2", "--board", "none", "--scenario", "stand-still"]


def _stale(folder: Path) -> None:
    """What an earlier run wrote (every file ridempc writes, a killed write's temporary
    file) and a user's own note."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in RUN_FILES:
        (folder / name).write_text("from an earlier run")
    (folder / ".log.npz.abc123.tmp").write_text("killed mid-write")
    (folder / "notes.txt").write_text("the user's own")


def test_a_ride_replaces_every_file_an_earlier_ride_wrote(capsys, tmp_path: Path) -> None:
    out = tmp_path / "ride"
    _stale(out)
    assert main([*SIM, "--out", str(out)]) == 0
    capsys.readouterr()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["files"] == ["log.npz"]
    left = sorted(p.name for p in out.iterdir())
    assert left == ["log.npz", "notes.txt", "summary.json"]
    assert (out / "notes.txt").read_text() == "the user's own"


def test_an_interrupted_ride_leaves_no_result_of_either_run(
    capsys, tmp_path: Path, monkeypatch
) -> None:
    class Interrupted(LimpController):
        def update(self, sensors, command):
            if sensors.time > 0.05:
                raise KeyboardInterrupt
            return super().update(sensors, command)

    monkeypatch.setitem(registry.CONTROLLERS, "interrupted", Interrupted)
    out = tmp_path / "ride"
    _stale(out)
    code = main([*SIM, "--controller", "interrupted", "--snapshots", "2", "--out", str(out)])
    capsys.readouterr()
    assert code == 130
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_compare_replaces_an_earlier_comparison_whatever_its_seeds(capsys, tmp_path: Path) -> None:
    out = tmp_path / "cmp"
    for name in COMPARISON_FILES:
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text("earlier")
    for controller, seeds in (("stand", 3), ("pd", 3), ("mpc", 1)):
        for seed in range(seeds):
            _stale(out / controller / f"seed-{seed}")
    (out / "mpc" / "seed-0" / "notes.txt").unlink()
    for seed in (1, 2):
        (out / "pd" / f"seed-{seed}" / "notes.txt").unlink()
    (out / "mpc" / "README").write_text("the user's own")
    code = main([*COMPARE, "--controllers", "stand,pd", "--duration", "0.2", "--out", str(out)])
    capsys.readouterr()
    assert code == 0
    assert json.loads((out / "comparison.json").read_text())["seeds"] == 1
    assert sorted(p.name for p in (out / "pd").iterdir()) == ["seed-0"]  # seeds 1, 2 gone
    assert sorted(p.name for p in (out / "stand").iterdir()) == ["seed-0", "seed-1", "seed-2"]
    for seed in (1, 2):  # only the user's notes are left of the earlier seeds 1 and 2
        assert [p.name for p in (out / "stand" / f"seed-{seed}").iterdir()] == ["notes.txt"]
    assert [p.name for p in (out / "mpc").iterdir()] == ["README"]  # its run removed


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--controllers", "stand,mpc"], ["cyberdog2", "none"]),  # the MPC has no such pair
        (["--controllers", "stand,pd,nope"], ["nope"]),
    ],
)
def test_compare_checks_every_controller_before_it_rides_any(
    capsys, tmp_path: Path, argv, words
) -> None:
    out = tmp_path / "cmp"
    code = main([*COMPARE, *argv, "--duration", "0.2", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    for word in words:
        assert word in err
    assert not out.exists()


def test_compare_checks_the_scenario_applies_before_it_rides(capsys, tmp_path: Path) -> None:
    out = tmp_path / "cmp"
    argv = ["compare", "--robot", "cyberdog2", "--board", "none", "--scenario", "push-off-0.5"]
    code = main([*argv, "--controllers", "stand,pd", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "push-off-0.5" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_failed_write_leaves_no_temporary_file(tmp_path: Path) -> None:
    def broken(stream) -> None:
        stream.write(b"half")
        raise OSError("disk full")

    with pytest.raises(OSError):
        atomic_write(tmp_path / "log.npz", broken)

    class BrokenFigure:
        def savefig(self, stream, **kwargs) -> None:
            stream.write(b"\x89PNG half")
            raise ValueError("renderer failed")

    with pytest.raises(ValueError):
        atomic_savefig(BrokenFigure(), tmp_path / "plots.png", dpi=90)
    assert list(tmp_path.iterdir()) == []


def test_sim_and_compare_never_share_a_folder_s_results(capsys, tmp_path: Path) -> None:
    out = tmp_path / "shared"
    assert main([*SIM, "--out", str(out)]) == 0
    argv = [*COMPARE, "--controllers", "stand,pd", "--duration", "0.2", "--out", str(out)]
    assert main(argv) == 0
    assert not (out / "summary.json").exists() and not (out / "log.npz").exists()
    assert main([*SIM, "--out", str(out)]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == ["log.npz", "summary.json"]


def test_bad_input_found_on_the_scene_keeps_the_earlier_results(capsys, tmp_path: Path) -> None:
    out = tmp_path / "cmp"
    argv = [*COMPARE, "--controllers", "stand,pd", "--duration", "0.2", "--out", str(out)]
    assert main(argv) == 0
    before = sorted(out.rglob("*"))
    scenario = tmp_path / "kick.toml"
    scenario.write_text('name = "kick"\nduration = 1.0\n[[disturbances]]\nt = 0.5\nbody = "tail"\n')
    bad = [a if a != "stand-still" else str(scenario) for a in argv]
    code = main(bad)
    err = capsys.readouterr().err
    assert code == 2 and "'tail'" in err and len(err.strip().splitlines()) == 1
    assert sorted(out.rglob("*")) == before


@pytest.mark.parametrize("name", [*RUN_FILES, *COMPARISON_FILES])
def test_a_folder_in_place_of_a_result_file_is_refused_first(capsys, tmp_path, name) -> None:
    out = tmp_path / "taken"
    _stale(out)
    (out / name).unlink(missing_ok=True)
    (out / name).mkdir()
    before = sorted(out.rglob("*"))
    for argv in ([*SIM, "--out", str(out)], [*COMPARE, "--controllers", "stand,pd", "--out",
                 str(out)]):  # fmt: skip
        code = main(argv)
        err = capsys.readouterr().err
        assert code == 2 and f"'{name}'" in err and len(err.strip().splitlines()) == 1, err
        assert sorted(out.rglob("*")) == before


def test_a_result_that_cannot_be_written_fails_with_one_line(capsys, tmp_path, monkeypatch) -> None:
    import ridempc.io

    def full(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(ridempc.io.os, "fsync", full)
    out = tmp_path / "full"
    code = main([*SIM, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and "No space left on device" in err and len(err.strip().splitlines()) == 1
    assert not (out / "summary.json").exists() and not list(out.glob(".*"))
