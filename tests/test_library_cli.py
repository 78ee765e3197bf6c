"""``ridempc library``: bad input exits 2 with one line; show prints and plots."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from ridempc.cli import main
from ridempc.library.store import library_folder


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        code = main(list(argv))
    except SystemExit as exc:  # argparse's errors: one line, exit 2
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (
            ["--robot", "cassie", "--board", "skateboard"],
            ["cassie-skateboard", "cyberdog2-skateboard"],
        ),
        (
            ["--robot", "cyberdog2", "--board", "skateboard", "--targets", "20"],
            ["20", "unreachable"],
        ),
        (["--robot", "cyberdog2", "--board", "skateboard", "--targets", "0.3,fast"], ["fast"]),
        (["--robot", "cyberdog2", "--board", "skateboard", "--jobs", "0"], ["--jobs"]),
    ],
)
def test_build_refuses_bad_input_with_one_line(capsys, tmp_path: Path, argv, words) -> None:
    code, _, err = _run(capsys, "library", "build", *argv, "--out", str(tmp_path / "lib"))
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for word in words:
        assert word in lines[0]
    assert not (tmp_path / "lib").exists()


def test_show_prints_the_table_and_plots(capsys, tmp_path: Path) -> None:
    plot = tmp_path / "entry.png"
    code, out, _ = _run(
        capsys,
        "library",
        "show",
        "--robot",
        "cyberdog2",
        "--board",
        "skateboard",
        "--entry",
        "accelerate-0.50",  # (a target alone is ambiguous: repush-0.50 has it too)
        "--plot",
        str(plot),
    )
    assert code == 0
    for word in ("accelerate-0.30", "accelerate-1.00", "Solve_Succeeded", "drift"):
        assert word in out
    assert plot.stat().st_size > 10_000


def test_show_refuses_a_tampered_library(capsys, tmp_path: Path) -> None:
    copy = tmp_path / "lib"
    shutil.copytree(library_folder("cyberdog2", "skateboard"), copy)
    entry = copy / "accelerate-0.70.npz"
    data = bytearray(entry.read_bytes())
    data[100] ^= 0x01
    entry.write_bytes(bytes(data))
    code, _, err = _run(
        capsys,
        "library",
        "show",
        "--robot",
        "cyberdog2",
        "--board",
        "skateboard",
        "--dir",
        str(copy),
    )
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "accelerate-0.70.npz" in lines[0] and "hash" in lines[0]


def test_show_unknown_entry_names_the_valid_ones(capsys) -> None:
    code, _, err = _run(
        capsys, "library", "show", "--robot", "cyberdog2", "--board", "skateboard", "--entry", "9.9"
    )
    assert code == 2
    assert "accelerate-0.30" in err and len(err.strip().splitlines()) == 1
