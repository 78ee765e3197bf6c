"""The runner under a sweep and a comparison: resume, failed rides, dead workers replaced.

The rides are fakes (module-level, so the worker processes find them); each appends its
variant and controller to ``calls.txt`` beside the rides, so that a test counts the rides
that really ran.
"""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

import pytest

from ridempc.scenarios.scenario import Scenario
from ridempc.sweep.engines import LocalEngine
from ridempc.sweep.runner import MAX_ATTEMPTS, RideTask, run_rides

SCENARIO = Scenario(name="test", duration=1.0)


def _tasks(folder: Path, variants: int, controllers: tuple[str, ...] = ("pd", "mpc")):
    return [
        RideTask(
            f"v{i:04d}",
            c,
            "cassie",
            "hovershoes",
            SCENARIO,
            seed=i,
            summary_path=folder / "rides" / f"v{i:04d}" / f"{c}.json",
        )  # fmt: skip
        for i in range(variants)
        for c in controllers
    ]


def _called(task: RideTask) -> None:
    with open(task.summary_path.parents[2] / "calls.txt", "a") as calls:
        calls.write(f"{task.variant} {task.controller}\n")


def fake_ride(task: RideTask) -> dict:
    _called(task)
    fell = task.seed % 2 == 1 and task.controller == "pd"
    return {"controller": task.controller, "seed": task.seed, "status": "ok", "fell": fell}


def raising_ride(task: RideTask) -> dict:
    if task.variant == "v0001":
        raise RuntimeError("the controller blew up")
    return fake_ride(task)


def dying_ride(task: RideTask) -> dict:
    """Kills its own worker the first time it rides v0001 pd."""
    marker = task.summary_path.parents[2] / "died"
    if task.variant == "v0001" and task.controller == "pd" and not marker.exists():
        marker.touch()
        os.kill(os.getpid(), signal.SIGKILL)
    return fake_ride(task)


def always_dying_ride(task: RideTask) -> dict:
    if task.variant == "v0000":
        os.kill(os.getpid(), signal.SIGKILL)
    return fake_ride(task)


def _calls(folder: Path) -> list[str]:
    path = folder / "calls.txt"
    return path.read_text().splitlines() if path.exists() else []


def _run(tasks, ride, workers: int = 2):
    engine = LocalEngine(workers)
    try:
        return run_rides(tasks, engine, ride=ride)
    finally:
        engine.close()


def test_every_ride_is_recorded_as_a_file(tmp_path: Path) -> None:
    tasks = _tasks(tmp_path, 3)
    summaries = _run(tasks, fake_ride)
    assert len(summaries) == 6 and len(_calls(tmp_path)) == 6
    for task in tasks:
        recorded = json.loads(task.summary_path.read_text())
        assert recorded == summaries[(task.variant, task.controller)]
        assert recorded["controller"] == task.controller


def test_a_restart_rides_only_what_is_missing(tmp_path: Path) -> None:
    tasks = _tasks(tmp_path, 4)
    _run(tasks[:5], fake_ride)  # an earlier run stopped after five rides
    (tmp_path / "calls.txt").unlink()
    summaries = _run(tasks, fake_ride)
    assert sorted(_calls(tmp_path)) == ["v0002 mpc", "v0003 mpc", "v0003 pd"]
    assert len(summaries) == 8
    _run(tasks, fake_ride)  # complete: nothing more
    assert len(_calls(tmp_path)) == 3


def test_a_half_written_summary_is_ridden_again(tmp_path: Path) -> None:
    tasks = _tasks(tmp_path, 1, ("pd",))
    tasks[0].summary_path.parent.mkdir(parents=True)
    tasks[0].summary_path.write_text('{"status": "o')  # not whole: never counted
    summaries = _run(tasks, fake_ride)
    assert _calls(tmp_path) == ["v0000 pd"] and summaries[("v0000", "pd")]["status"] == "ok"


def test_a_failed_ride_is_recorded_and_the_sweep_goes_on(tmp_path: Path) -> None:
    tasks = _tasks(tmp_path, 3)
    summaries = _run(tasks, raising_ride)
    failed = {k: s for k, s in summaries.items() if s["status"] == "failed"}
    assert set(failed) == {("v0001", "pd"), ("v0001", "mpc")}
    assert "RuntimeError: the controller blew up" in failed[("v0001", "pd")]["error"]
    assert len(_calls(tmp_path)) == 4  # every other ride ran
    recorded = json.loads(tasks[2].summary_path.read_text())
    assert recorded["status"] == "failed" and recorded["fell"] is False


def test_a_dead_worker_is_replaced_and_its_ride_redone(tmp_path: Path) -> None:
    tasks = _tasks(tmp_path, 3)
    summaries = _run(tasks, dying_ride)
    assert (tmp_path / "died").exists()
    assert all(s["status"] == "ok" for s in summaries.values()) and len(summaries) == 6
    assert _calls(tmp_path).count("v0001 pd") == 1  # the killed try wrote nothing


@pytest.mark.parametrize("workers", [1, 2])
def test_a_ride_that_always_kills_its_worker_is_failed(tmp_path: Path, workers: int) -> None:
    tasks = _tasks(tmp_path, 3, ("pd",))
    summaries = _run(tasks, always_dying_ride, workers=workers)
    assert summaries[("v0000", "pd")]["status"] == "failed"
    assert f"died {MAX_ATTEMPTS} times" in summaries[("v0000", "pd")]["error"]
    others = [summaries[(f"v000{i}", "pd")]["status"] for i in (1, 2)]
    assert others == ["ok", "ok"]  # those that shared the pool with it ride again, alone
