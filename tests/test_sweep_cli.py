"""``ridempc sweep`` end to end: a tiny real sweep, its resume, bad input, an interrupt."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ridempc.cli import main
from ridempc.sweep.stats import deterministic

# Pushes and a floor within a one-second ride.
SHORT = """
name = "short"
[[pushes]]
magnitude = {uniform = [0.0, 2.0]}
direction = {uniform = [0.0, 360.0]}
t = {uniform = [0.2, 0.6]}
duration = 0.2
[[changes]]
parameter = "floor_friction"
value = {uniform = [0.6, 1.0]}
"""


def _args(tmp_path: Path, out: Path, *more: str) -> list[str]:
    distribution = tmp_path / "short.toml"
    if not distribution.exists():
        distribution.write_text(SHORT)
    return ["sweep", "--robot", "cassie", "--board", "hovershoes", "--scenario", "stand-still",
            "--distribution", str(distribution), "--samples", "2", "--controllers", "pd",
            "--duration", "1", "--workers", "2", "--out", str(out), *more]  # fmt: skip


def test_a_tiny_sweep_writes_every_file_and_resumes(tmp_path: Path, capsys) -> None:
    out = tmp_path / "sweep"
    assert main(_args(tmp_path, out)) == 0
    printed = capsys.readouterr().out
    assert "| pd | 2/2 |" in printed and "2 rides in" in printed
    for name in ("sweep.toml", "sweep.json", "report.md", "report.html"):
        assert (out / name).stat().st_size > 0, name
    result = json.loads((out / "sweep.json").read_text())
    assert result["samples"] == 2 and result["failed"] == 0
    pd = result["controllers"]["pd"]
    assert pd["rides"] == 2 and pd["survival_rate"] == 1.0 and pd["survival_ci95"][1] == 1.0
    assert 0.0 < pd["survival_ci95"][0] < 1.0 and pd["worker_peak_rss_mib"] > 0.0
    for variant in result["variants"]:
        assert set(variant["drawn"]) >= {"push.magnitude", "push.direction", "push.t"}
        assert (out / variant["scenario_file"]).is_file()
        recorded = json.loads((out / "rides" / variant["id"] / "pd.json").read_text())
        assert recorded == variant["summaries"]["pd"] and recorded["seed"] == variant["seed"]
    report = (out / "report.md").read_text()
    assert "ridempc sim --robot cassie --board hovershoes --controller pd --scenario" in report
    assert (out / "report.html").read_text().count("data:image/png;base64,") >= 3

    (out / "rides" / "v0001" / "pd.json").unlink()  # as if killed during that ride
    assert main(_args(tmp_path, out)) == 0
    assert "1 rides in" in capsys.readouterr().out  # only the missing one
    again = json.loads((out / "sweep.json").read_text())
    for before, after in zip(result["variants"], again["variants"], strict=True):
        assert deterministic(before["summaries"]["pd"]) == deterministic(after["summaries"]["pd"])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (["--distribution", "nope"], "unknown distribution 'nope'"),
        (["--controllers", "pd,nope"], "unknown controller 'nope'"),
        (["--controllers", "pd,pd"], "names a controller twice"),
        (["--address", "tcp://127.0.0.1:9"], "--address tcp://127.0.0.1:9: the local engine"),
        (["--scenario", "wave", "--board", "segway"], "scenario 'wave' does not apply"),
    ],
)
def test_bad_input_is_one_line_before_anything(tmp_path, capsys, change, message) -> None:
    out = tmp_path / "sweep"
    args = _args(tmp_path, out)
    for option, value in zip(change[::2], change[1::2], strict=True):
        if option in args:
            args[args.index(option) + 1] = value
        else:
            args += [option, value]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("ridempc: error: ") and err.count("\n") == 1 and message in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [("--samples", "0", "--samples: 0 is out of range"),
     ("--engine", "ray", "--engine: invalid choice: 'ray'"),
     ("--workers", "0", "--workers: 0 is out of range")],
)  # fmt: skip
def test_bad_numbers_are_one_line(tmp_path, capsys, option, value, message) -> None:
    args = _args(tmp_path, tmp_path / "sweep")
    if option in args:
        args[args.index(option) + 1] = value
    else:
        args += [option, value]
    with pytest.raises(SystemExit) as exited:
        main(args)
    err = capsys.readouterr().err
    assert exited.value.code == 2 and err.count("\n") == 1 and message in err


def test_an_inverted_range_and_another_sweeps_folder_are_refused(tmp_path, capsys) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(SHORT.replace("[0.0, 2.0]", "[2.0, 0.0]"))
    args = _args(tmp_path, tmp_path / "a")
    args[args.index("--distribution") + 1] = str(bad)
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(bad) in err and "magnitude" in err
    assert not (tmp_path / "a").exists()

    out = tmp_path / "b"
    out.mkdir()
    (out / "sweep.toml").write_text(
        'robot = "cassie"\nboard = "hovershoes"\nscenario = "stand-still"\n'
        'scenario_sha256 = "x"\ndistribution = "d"\ndistribution_sha256 = "y"\n'
        'controllers = ["pd"]\nseed = 7\n'
    )
    assert main(_args(tmp_path, out)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "this folder holds a sweep with" in err
    assert sorted(p.name for p in out.iterdir()) == ["sweep.toml"]


def test_an_interrupt_keeps_the_finished_rides_and_claims_nothing(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    args = _args(tmp_path, out)
    args[args.index("--samples") + 1] = "20"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    process = subprocess.Popen(
        [sys.executable, "-m", "ridempc.cli", *args],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True,
    )  # fmt: skip
    while not list(out.glob("rides/*/pd.json")) and process.poll() is None:
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=30)
    assert process.returncode == 130
    assert "ridempc: interrupted (SIGINT); no sweep.json was written" in err
    assert "Traceback" not in err
    assert not (out / "sweep.json").exists() and not (out / "report.md").exists()
    rides = list(out.glob("rides/*/pd.json"))
    assert 1 <= len(rides) < 20
    for ride in rides:
        assert json.loads(ride.read_text())["status"] == "ok"  # each a whole file
    assert not list(out.glob("rides/*/.*.tmp"))


def test_compare_rides_through_the_runner_with_workers(tmp_path: Path, capsys) -> None:
    args = ["compare", "--robot", "cyberdog2", "--board", "none", "--scenario", "stand-still",
            "--controllers", "stand,pd", "--seeds", "2", "--duration", "0.5"]  # fmt: skip
    assert main([*args, "--out", str(tmp_path / "one")]) == 0
    assert main([*args, "--workers", "2", "--out", str(tmp_path / "two")]) == 0
    capsys.readouterr()
    for controller in ("stand", "pd"):
        for seed in (0, 1):
            one, two = (
                json.loads(
                    (tmp_path / n / controller / f"seed-{seed}" / "summary.json").read_text()
                )
                for n in ("one", "two")
            )
            assert deterministic(one) == deterministic(two) and one["worker_peak_rss_mib"] > 0.0
