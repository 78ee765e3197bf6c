"""``ridempc margin``: the bisection against known thresholds, its files, bad input, and one
tiny real search through the command line."""

from __future__ import annotations

import json
import math
import signal
import time
from pathlib import Path

import pytest

from ridempc.scenarios import resolve_scenario
from ridempc.sweep.bisection import Outcome, Search, find_margin
from ridempc.sweep.margin import MarginSpec, run_margin
from ridempc.sweep.pushes import directions, pushed_scenario
from tests.test_cli import _run
from tests.test_interrupts import SETTLE_S, _assert_interrupted, _start, _stop, _wait_for

SEARCH = Search(tolerance=0.1, start=1.0, cap=32.0, checks=2)


def _threshold(threshold: float, dip: tuple[float, float] | None = None):
    """A fake ride: survives pushes up to ``threshold`` [N/kg], except inside ``dip``."""

    def ride(magnitude: float) -> Outcome:
        if dip is not None and dip[0] < magnitude < dip[1]:
            return Outcome("fell", fall_time_s=3.5)
        return Outcome("ok") if magnitude <= threshold else Outcome("fell", fall_time_s=3.4)

    return ride


@pytest.mark.parametrize("threshold", [0.05, 0.73, 1.0, 3.41, 7.9, 20.0, 31.95])
def test_bisection_finds_a_known_threshold_within_the_tolerance(threshold: float) -> None:
    margin = find_margin(_threshold(threshold), SEARCH)
    assert threshold - SEARCH.tolerance <= margin.margin <= threshold
    assert margin.monotone and not margin.capped and margin.margin == margin.boundary
    assert margin.lowest_fall is not None and margin.lowest_fall - margin.margin <= 0.1 + 1e-9
    bisections = [t for t in margin.trials if t.phase == "bisect"]
    assert len(bisections) <= math.ceil(math.log2(16.0 / SEARCH.tolerance))
    assert len({t.magnitude for t in margin.trials}) == len(margin.trials)  # none twice


def test_a_rider_that_survives_the_cap_is_reported_capped() -> None:
    margin = find_margin(_threshold(100.0), SEARCH)
    assert margin.capped and margin.margin == 32.0 and margin.lowest_fall is None
    assert [t.magnitude for t in margin.trials if t.phase == "bracket"] == [1, 2, 4, 8, 16, 32]


def test_a_fall_below_the_boundary_is_reported_non_monotone() -> None:
    # survives up to 6 N/kg but falls between 2.6 and 3.4: the bracket (1, 2, 4, 8) and the
    # bisection jump over the dip, the first check rides the widest gap below 6: 3 N/kg
    margin = find_margin(_threshold(6.0, dip=(2.6, 3.4)), SEARCH)
    assert not margin.monotone
    assert margin.lowest_fall is not None and 2.6 < margin.lowest_fall < 3.4
    assert margin.margin < margin.lowest_fall < margin.boundary
    assert any(t.phase == "check" and not t.survived for t in margin.trials)


def test_without_checks_a_jumped_dip_goes_unseen() -> None:
    margin = find_margin(_threshold(6.0, dip=(2.6, 3.4)), Search(0.1, 1.0, 32.0, checks=0))
    assert margin.monotone and 5.9 <= margin.margin <= 6.0


def test_a_failed_ride_is_not_counted_as_survived() -> None:
    def ride(magnitude: float) -> Outcome:
        return Outcome("failed", error="boom") if magnitude >= 4.0 else Outcome("ok")

    margin = find_margin(ride, SEARCH)
    assert 3.9 <= margin.margin < 4.0 and margin.failed >= 1
    assert all(t.outcome.error == "boom" for t in margin.trials if not t.survived)


def test_directions_are_evenly_spaced_from_forward() -> None:
    assert directions(8) == (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0)
    scenario = pushed_scenario(resolve_scenario("stand-still"), 90.0, 2.5, 3.0, 4.0)
    push = scenario.disturbances[-1]
    assert push.force == (0.0, 2.5, 0.0) and push.per_kg and push.duration == 0.2
    assert push.t == 3.0 and scenario.duration == 7.0 and push.body == "base"


def _fake_ride(spec: MarginSpec, degrees: float, magnitude: float) -> Outcome:
    """A rider whose margin is 2 N/kg forward and back, 1 N/kg sideways (module level:
    the worker processes find it by name)."""
    threshold = 1.0 + abs(math.cos(math.radians(degrees)))
    return Outcome("ok") if magnitude <= threshold else Outcome("fell", fall_time_s=3.5)


def _spec(directions: int = 4) -> MarginSpec:
    return MarginSpec(
        robot="cassie",
        board="hovershoes",
        controller="pd",
        scenario=resolve_scenario("stand-still", "hovershoes"),
        seed=0,
        directions=directions,
        push_time=3.0,
        duration_after=4.0,
        search=SEARCH,
    )


@pytest.mark.parametrize("workers", [1, 2])
def test_directions_are_searched_in_parallel_with_the_same_result(workers: int) -> None:
    result = run_margin(_spec(), workers, ride=_fake_ride)
    assert list(result.margins) == [0.0, 90.0, 180.0, 270.0]
    expected = {0.0: 2.0, 90.0: 1.0, 180.0: 2.0, 270.0: 1.0}
    for degrees, margin in result.margins.items():
        assert expected[degrees] - 0.1 <= margin.margin <= expected[degrees]
    assert result.unpushed.survived and result.failed == 0


BASE = ("margin", "--robot", "cassie", "--board", "hovershoes", "--controller", "pd")


@pytest.mark.parametrize(
    ("change", "named"),
    [
        (("--robot", "atlas"), "atlas"),
        (("--board", "surfboard"), "surfboard"),
        (("--controller", "magic"), "magic"),
        (("--scenario", "moonwalk"), "moonwalk"),
        (("--scenario", "push-off-0.5"), "push-off-0.5"),
        (("--directions", "0"), "--directions"),
        (("--directions", "1000"), "--directions"),
        (("--tolerance", "0"), "--tolerance"),
        (("--tolerance", "-0.1"), "--tolerance"),
        (("--tolerance", "nan"), "--tolerance"),
        (("--max-push", "inf"), "--max-push"),
        (("--duration-after", "0"), "--duration-after"),
        (("--workers", "0"), "--workers"),
    ],
)
def test_bad_input_is_one_line_and_exit_2_before_any_ride(
    capsys, tmp_path: Path, monkeypatch, change: tuple[str, str], named: str
) -> None:
    def no_ride(*args: object) -> Outcome:
        raise AssertionError("a ride started")

    monkeypatch.setattr("ridempc.sweep.margin.ride_pushed", no_ride)
    argv = dict(zip(BASE[1::2], BASE[2::2], strict=True))
    argv[change[0]] = change[1]
    out = tmp_path / "m"
    code, _, err = _run(
        capsys, "margin", *[x for kv in argv.items() for x in kv], "--out", str(out)
    )
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ridempc: error:") and named in lines[0]
    assert not out.exists()


def test_an_unwritable_out_is_one_line_and_exit_2(capsys, tmp_path: Path) -> None:
    taken = tmp_path / "file"
    taken.write_text("not a folder")
    code, _, err = _run(capsys, *BASE, "--out", str(taken))
    assert code == 2 and len(err.strip().splitlines()) == 1 and str(taken) in err


@pytest.fixture
def fake_rides(monkeypatch) -> None:
    """Every ride of the command is :func:`_fake_ride` (no simulation)."""
    monkeypatch.setattr("ridempc.sweep.margin.ride_pushed", _fake_ride)


def test_the_command_writes_the_margins_every_ride_and_the_plot(
    capsys, tmp_path: Path, fake_rides
) -> None:
    out = tmp_path / "m"
    code, printed, err = _run(
        capsys, *BASE, "--directions", "4", "--workers", "2", "--out", str(out)
    )
    assert code == 0, err
    payload = json.loads((out / "margin.json").read_text())
    assert payload["margins"].keys() == {"0", "90", "180", "270"}
    assert 1.9 <= payload["margins"]["0"] <= 2.0 and 0.9 <= payload["margins"]["90"] <= 1.0
    assert payload["push_duration_s"] == 0.2 and payload["tolerance"] == 0.1
    assert (payload["robot"], payload["board"], payload["controller"]) == BASE[2::2]
    assert payload["scenario"] == "stand-still" and payload["seed"] == 0
    assert all(payload["monotone"].values()) and payload["failed_rides"] == 0
    for key, rides in payload["rides"].items():
        assert {r["survived"] for r in rides} == {True, False}
        for r in rides:  # each ride replays from its scenario file
            scenario = resolve_scenario(str(out / r["scenario_file"]))
            assert scenario == pushed_scenario(
                resolve_scenario("stand-still", "hovershoes"), float(key), r["magnitude"]
            )
    assert (out / "margin.png").read_bytes().startswith(b"\x89PNG")
    lines = printed.splitlines()
    assert any(line.split()[:2] == ["90", f"{payload['margins']['90']:.2f}"] for line in lines)


def test_a_second_run_replaces_the_first_ones_files(capsys, tmp_path: Path, fake_rides) -> None:
    out = tmp_path / "m"
    assert _run(capsys, *BASE, "--directions", "4", "--workers", "1", "--out", str(out))[0] == 0
    notes = out / "notes.txt"
    notes.write_text("mine")
    assert _run(capsys, *BASE, "--directions", "1", "--workers", "1", "--out", str(out))[0] == 0
    assert sorted(p.name for p in (out / "rides").iterdir()) == ["0", "unpushed.toml"]
    assert json.loads((out / "margin.json").read_text())["margins"].keys() == {"0"}
    assert notes.read_text() == "mine"


def test_a_tiny_real_search_through_the_command_line(capsys, tmp_path: Path) -> None:
    """The dog standing on the ground, two directions, half a second after the push, a coarse
    tolerance: about ten one-second rides."""
    out = tmp_path / "m"
    argv = ["margin", "--robot", "cyberdog2", "--board", "none", "--controller", "stand"]
    options = ["--directions", "2", "--push-time", "0.5", "--duration-after", "0.5"]
    options += ["--tolerance", "4", "--checks", "0", "--workers", "1"]
    code, _, err = _run(capsys, *argv, *options, "--out", str(out))
    assert code == 0, err
    payload = json.loads((out / "margin.json").read_text())
    assert payload["unpushed"]["survived"] and payload["margins"].keys() == {"0", "180"}
    for key, margin in payload["margins"].items():
        rides = payload["rides"][key]
        assert rides[0]["magnitude"] == 1.0 and rides[0]["survived"]  # the library's push
        assert 1.0 <= margin <= 32.0


def _crashing_ride(spec: MarginSpec, degrees: float, magnitude: float) -> Outcome:
    """:func:`_fake_ride`, but the controller crashes on pushes of 1.5 N/kg and more."""
    if magnitude >= 1.5:
        return Outcome("failed", error="ValueError: the controller crashed")
    return _fake_ride(spec, degrees, magnitude)


def test_a_failed_ride_is_recorded_and_the_command_exits_1(
    capsys, tmp_path: Path, monkeypatch
) -> None:
    monkeypatch.setattr("ridempc.sweep.margin.ride_pushed", _crashing_ride)
    out = tmp_path / "m"
    code, _, err = _run(capsys, *BASE, "--directions", "2", "--workers", "1", "--out", str(out))
    assert code == 1 and err.startswith("ridempc: failed:") and "Traceback" not in err
    payload = json.loads((out / "margin.json").read_text())
    assert payload["failed_rides"] >= 2 and payload["margins"]["0"] < 1.5
    failed = [r for r in payload["rides"]["0"] if r["status"] == "failed"]
    assert failed and not any(r["survived"] for r in failed)
    assert failed[0]["error"] == "ValueError: the controller crashed"


@pytest.mark.parametrize(("signum", "workers"), [(signal.SIGINT, "2"), (signal.SIGTERM, "1")])
def test_an_interrupted_search_writes_no_margin_json(
    tmp_path: Path, signum: int, workers: str
) -> None:
    out = tmp_path / "m"
    process = _start(*BASE, "--directions", "2", "--workers", workers, "--out", str(out))
    _wait_for(out, process)  # made once everything is checked, before the first ride
    time.sleep(SETTLE_S)
    seconds, _, err = _stop(process, signum)
    _assert_interrupted(process, seconds, err, signum, f"no margin.json was written in {out}")
    assert not (out / "margin.json").exists()
