"""Every numeric option and every path argument of every command, refused before any work.

Generated over the options and path arguments: each bad value of each class (not a number,
NaN, infinities, out of range; missing, a folder for a file, a file for a folder, a file in
place of a parent folder, unwritable, unreadable, not UTF-8) must end the command with exit
code 2, one line ``ridempc: error: ...`` naming the option or path, and nothing written.
The work itself (simulation, bench, identification, library build) is replaced by a stub
that fails the test if it is reached.
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

import ridempc.library.build
import ridempc.run
from ridempc import bench
from ridempc.cli import main
from ridempc.options import MAX_JOBS, MAX_SEED, MAX_SEEDS, MAX_SNAPSHOTS
from ridempc.units import MAX_DURATION

SIM = ["sim", "--robot", "cyberdog2"]
COMPARE = ["compare", "--robot", "cyberdog2", "--board", "none", "--scenario", "stand-still",
           "--controllers", "stand,pd"]  # fmt: skip
BENCH = ["bench", "--pairs", "cassie-segway"]
IDENTIFY = ["board", "identify", "--board", "segway"]
BUILD = ["library", "build", "--robot", "cyberdog2", "--board", "skateboard"]
SHOW = ["library", "show", "--robot", "cassie", "--board", "segway"]
SWEEP = ["sweep", "--robot", "cassie", "--board", "hovershoes", "--samples", "2",
         "--controllers", "pd"]  # fmt: skip
SCENARIO = ["--scenario", "stand-still"]
DISTRIBUTION = ["--distribution", "everyday"]


@pytest.fixture(autouse=True)
def no_work(monkeypatch) -> None:
    """Any simulation, bench, identification or build started fails the test."""

    def started(*args, **kwargs):
        raise AssertionError("work started before the bad input was refused")

    monkeypatch.setattr(ridempc.run, "build_scene", started)
    monkeypatch.setattr(bench, "bench_pair", started)
    segway = importlib.import_module("ridempc.boards.segway")
    monkeypatch.setattr(segway, "KIND", segway.KIND._replace(identify=started))
    monkeypatch.setattr(ridempc.library.build, "solve_entry", started)


def _refused(capsys, argv: list[str]) -> str:
    """The one line of a refused command (exit code 2, whether argparse or ridempc saw it)."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    assert code == 2, (argv, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ridempc: error: "), err
    return lines[0]


NOT_NUMBERS = ("x", "nan", "NaN", "inf", "-inf", "1e999", "")

# (command, option, extra arguments, bad values of its range)
NUMERIC_OPTIONS = [
    (SIM, "--duration", ["--out", "{out}"], ["0", "-1", "1e-9", str(MAX_DURATION * 1.01)]),
    (SIM, "--seed", ["--out", "{out}"], ["-1", str(MAX_SEED + 1), "1.5", "true"]),
    (SIM, "--snapshots", ["--out", "{out}"], ["-1", str(MAX_SNAPSHOTS + 1), "2.0"]),
    (COMPARE, "--seeds", ["--out", "{out}"], ["0", "-3", str(MAX_SEEDS + 1), "1.5"]),
    (COMPARE, "--duration", ["--out", "{out}"], ["0", str(MAX_DURATION + 1)]),
    (BENCH, "--seconds", [], ["0", "-2", "1e6"]),
    (BUILD, "--jobs", ["--out", "{out}"], ["0", str(MAX_JOBS + 1), "2.5"]),
    (BUILD, "--targets", ["--out", "{out}"], ["0.3,nan", "inf", "0.3,", "20", "0.3,0.3"]),
    (SHOW, "--entry", [], ["nan", "inf", "-inf"]),
]


def _numeric_cases():
    for command, option, extra, bad in NUMERIC_OPTIONS:
        values = [*NOT_NUMBERS, *bad] if option not in ("--entry", "--targets") else bad
        for value in values:
            yield pytest.param(command, option, extra, value, id=f"{command[0]} {option}={value}")


@pytest.mark.parametrize(("command", "option", "extra", "value"), list(_numeric_cases()))
def test_bad_numbers_are_refused(capsys, tmp_path: Path, command, option, extra, value) -> None:
    out = tmp_path / "out"
    extra = [a.replace("{out}", str(out)) for a in extra]
    line = _refused(capsys, [*command, f"{option}={value}", *extra])
    assert option in line or "target" in line, line
    assert not out.exists()


# (command, path option, what the argument is, the rest of the command line)
PATH_ARGUMENTS = [
    (SIM, "--scenario", "file to read", ["--out", "{tmp}/o"]),
    (SIM, "--out", "folder to write", []),
    (COMPARE, "--out", "folder to write", []),
    (
        ["compare", "--robot", "cyberdog2", "--board", "none", "--controllers", "stand,pd"],
        "--scenario",
        "file to read",
        ["--out", "{tmp}/o"],
    ),  # fmt: skip
    (BENCH, "--json", "file to write", []),
    (BENCH, "--scenario", "file to read", []),
    (IDENTIFY, "--json", "file to write", []),
    (BUILD, "--out", "folder to write", []),
    (SHOW, "--dir", "folder to read", []),
    (SHOW + ["--entry", "0.5"], "--plot", "file to write", []),
    (SWEEP + [*SCENARIO, *DISTRIBUTION], "--out", "folder to write", []),
    (SWEEP + DISTRIBUTION, "--scenario", "file to read", ["--out", "{tmp}/o"]),
    (SWEEP + SCENARIO, "--distribution", "file to read", ["--out", "{tmp}/o"]),
]


# The classes of bad path for each role of a path argument.
CLASSES: dict[str, tuple[str, ...]] = {
    "file to read": ("file in place of a parent", "folder for a file", "missing", "not UTF-8",
                     "a pipe", "unreadable"),
    "folder to read": ("file in place of a parent", "file for a folder", "missing",
                       "unreadable"),
    "file to write": ("file in place of a parent", "folder for a file", "in a missing folder",
                      "a device", "unwritable", "unwritable folder"),
    "folder to write": ("file in place of a parent", "file for a folder", "unwritable",
                        "unwritable folder"),
}  # fmt: skip


def _bad_path(tmp: Path, case: str) -> Path:
    """A path of that class under ``tmp`` (made now, before the command runs)."""
    a_file = tmp / "a-file.toml"
    a_file.write_text('name = "x"\n')
    a_folder = tmp / "a-folder.png"
    a_folder.mkdir()
    locked = tmp / "locked"
    locked.mkdir()
    (locked / "inside.toml").write_text('name = "x"\n')
    locked.chmod(0)
    binary = tmp / "binary.toml"
    binary.write_bytes(b'name = "\xff\xfe"\n\x00\x01')
    os.mkfifo(tmp / "pipe.toml")  # reading it would wait for a writer forever
    return {
        "file in place of a parent": a_file / "below.png",
        "folder for a file": a_folder,
        "file for a folder": a_file,
        "missing": tmp / "missing" / "nothing.toml",
        "not UTF-8": binary,
        "a pipe": tmp / "pipe.toml",
        "a device": Path("/dev/null"),  # replaced by a file if it were taken
        "in a missing folder": tmp / "missing" / "out.png",
        "unwritable": Path("/proc/ridempc-test/out.png"),  # refused to root too
        "unreadable": locked / "inside.toml",
        "unwritable folder": locked / "out.png",
    }[case]


def _path_cases():
    for command, option, role, extra in PATH_ARGUMENTS:
        for case in CLASSES[role]:
            name = f"{' '.join(command[:2])} {option}: {case}"
            yield pytest.param(command, option, extra, case, id=name)


@pytest.mark.parametrize(("command", "option", "extra", "case"), list(_path_cases()))
def test_bad_paths_are_refused_before_any_work(
    capsys, tmp_path: Path, command, option, extra, case
) -> None:
    if case in ("unreadable", "unwritable folder") and os.geteuid() == 0:
        pytest.skip("root reads and writes whatever the mode bits say")
    path = _bad_path(tmp_path, case)
    locked = tmp_path / "locked"
    locked.chmod(0o755)
    before = sorted(tmp_path.rglob("*"))
    locked.chmod(0)
    extra = [a.replace("{tmp}", str(tmp_path)) for a in extra]
    try:
        line = _refused(capsys, [*command, option, str(path), *extra])
    finally:
        locked.chmod(0o755)
    assert str(path) in line or option in line, line
    assert sorted(tmp_path.rglob("*")) == before  # nothing written


@pytest.mark.parametrize(
    ("command", "option", "extra"),
    [a[:2] + (a[3],) for a in PATH_ARGUMENTS if a[1] not in ("--scenario", "--distribution")],
    # (a name or a path)
)
def test_an_empty_path_is_refused(capsys, tmp_path: Path, command, option, extra) -> None:
    extra = [a.replace("{tmp}", str(tmp_path)) for a in extra]
    line = _refused(capsys, [*command, option, "", *extra])
    assert option in line


def test_a_scenario_path_that_does_not_exist_says_file_not_found(capsys, tmp_path) -> None:
    for name in ("nope.toml", "NOPE.TOML", str(tmp_path / "nope")):
        line = _refused(capsys, [*SIM, "--scenario", name, "--out", str(tmp_path / "o")])
        assert "not found" in line and "unknown scenario" not in line


@pytest.mark.parametrize(
    "argv",
    [
        [*SIM, "--duration=nan", "--out", "{tmp}/o"],
        [*SIM, "--seed", "-1", "--out", "{tmp}/o"],
        [*SIM, "--scenario", "{tmp}/binary.toml", "--out", "{tmp}/o"],
        [*SIM, "--scenario", "{tmp}/nan.toml", "--out", "{tmp}/o"],
        [*SIM, "--out", "/proc/ridempc-test"],
        ["sim", "--robot"],
        ["library", "show", "--robot", "cassie", "--board", "segway", "--dir", "{tmp}"],
    ],
    ids=[
        "nan duration",
        "negative seed",
        "binary scenario",
        "nan in scenario",
        "proc out",
        "missing value",
        "empty library",
    ],  # fmt: skip
)
def test_the_installed_command_prints_one_line_and_no_traceback(tmp_path: Path, argv) -> None:
    (tmp_path / "binary.toml").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    (tmp_path / "nan.toml").write_text('name = "n"\nduration = nan\n')
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    done = subprocess.run(
        [sys.executable, "-m", "ridempc.cli", *argv],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ridempc: error: "), done.stderr
    assert not (tmp_path / "o").exists()


def test_a_file_too_large_to_be_a_description_is_refused(capsys, tmp_path, monkeypatch) -> None:
    import ridempc.checks

    monkeypatch.setattr(ridempc.checks, "MAX_TEXT_BYTES", 16)
    scenario = tmp_path / "big.toml"
    scenario.write_text('name = "big"\nduration = 1.0\n')
    line = _refused(capsys, [*SIM, "--scenario", str(scenario), "--out", str(tmp_path / "o")])
    assert "at most 16 bytes" in line


@pytest.mark.parametrize("damage", ["not UTF-8", "a folder", "not TOML", "missing MJCF"])
@pytest.mark.parametrize("which", ["robots/cassie/robot.toml", "boards/segway/board.toml"])
def test_a_damaged_robot_or_board_file_is_one_line(
    capsys, tmp_path: Path, monkeypatch, which, damage
) -> None:
    """The robot and board descriptions a user edits, read through the same checks."""
    import shutil

    import ridempc.paths

    root = tmp_path / "data"
    for folder in ("robots", "boards"):
        shutil.copytree(ridempc.paths.data_root() / folder, root / folder)
    monkeypatch.setattr(ridempc.paths, "data_root", lambda: root)
    target = root / which
    if damage == "not UTF-8":
        target.write_bytes(b"\xff\xfe\x00binary")
    elif damage == "a folder":
        target.unlink()
        target.mkdir()
    elif damage == "not TOML":
        target.write_text("name = \n")
    else:
        (root / "robots" / "cassie" / "cassie.xml").unlink()
    argv = ["sim", "--robot", "cassie", "--board", "segway", "--controller", "stand"]
    line = _refused(capsys, [*argv, "--out", str(tmp_path / "o")])
    assert str(root) in line, line
    assert not (tmp_path / "o").exists()
