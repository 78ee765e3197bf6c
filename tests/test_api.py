"""The Python API (ridempc.api.ride): names, a user's own controller object, a scenario
object, no output at all or exactly what ``ridempc sim`` writes, bad input before anything
rides, interrupts as for the command. Rides of half a second of Cassie standing."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import ridempc
from ridempc.controllers.base import Controller
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.robots import load_robot
from ridempc.scenarios import Scenario, resolve_scenario
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket
from ridempc.sim.simulation import Simulation

ROOT = Path(__file__).resolve().parents[1]
SHORT = 0.5  # [s] of riding: enough for the summary's figures
STOP_S = 5.0  # [s] from the signal to the process's end: a hang, not a slow machine


class Hold(Controller):
    """A user's controller: the smallest one that stands, each motor's PD on the posture it
    starts in (the interface of the API's docstring, nothing of ridempc's own riders)."""

    rate_hz = 500.0
    name = "hold"

    def __init__(self, robot, board: str = "none") -> None:
        super().__init__(robot, board)
        self.ticks = 0
        self._hold: MotorCommand | None = None

    def reset(self, sensors: SensorPacket) -> None:
        n = len(self.robot.motors)
        self._hold = MotorCommand.hold(self.robot.motors, np.array(sensors.joint_position[:n]))

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        assert self._hold is not None
        self.ticks += 1
        return self._hold

    def summary(self) -> dict[str, int]:
        return {"hold_ticks": self.ticks}


@pytest.fixture
def empty_cwd(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_a_named_ride_without_out_writes_nothing(empty_cwd: Path) -> None:
    summary = ridempc.ride("cassie", "none", "stand", duration=SHORT, seed=np.int64(1))
    assert summary["status"] == "ok" and not summary["fell"]
    assert summary["controller"] == "stand" and summary["scenario"] == "stand-still"
    assert summary["seed"] == 1 and summary["sim_time_s"] == pytest.approx(SHORT)
    assert summary["files"] == []
    assert list(empty_cwd.iterdir()) == []
    json.dumps(summary)  # serialisable, as summary.json is


def test_a_users_controller_object_rides(empty_cwd: Path) -> None:
    controller = Hold(load_robot("cassie"), "none")
    summary = ridempc.ride("cassie", "none", controller, "stand-still", duration=SHORT)
    assert summary["status"] == "ok" and not summary["fell"]
    assert summary["controller"] == "hold" and summary["controller_hz"] == 500.0
    assert summary["hold_ticks"] == controller.ticks == round(SHORT * 500.0)
    assert list(empty_cwd.iterdir()) == []


def test_a_scenario_object_and_out_write_what_sim_writes(tmp_path: Path) -> None:
    scenario = resolve_scenario("push", "none").with_duration(SHORT)
    summary = ridempc.ride("cassie", "none", "stand", scenario, out=tmp_path / "run", seed=2)
    assert summary["scenario"] == "push" and summary["duration_s"] == SHORT
    written = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert written == summary and summary["files"] == ["log.npz"]  # plots only if asked
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["log.npz", "summary.json"]


def test_the_same_seed_gives_the_same_ride(empty_cwd: Path) -> None:
    scenario = Path(ROOT / "ridempc/scenarios/library/stand-still.toml")
    first, second = (
        ridempc.ride("cassie", "none", "stand", scenario, duration=SHORT, seed=5) for _ in "ab"
    )
    drop = ("wall_time_s", "real_time_factor", "controller_update_ms")
    assert {k: v for k, v in first.items() if k not in drop} == {
        k: v for k, v in second.items() if k not in drop
    }


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        ({"robot": "walle"}, UnknownNameError, "unknown robot 'walle'"),
        ({"board": "surfboard"}, UnknownNameError, "unknown board 'surfboard'"),
        ({"controller": "lqr"}, UnknownNameError, "unknown controller 'lqr'"),
        ({"scenario": "loop"}, UnknownNameError, "unknown scenario 'loop'"),
        ({"scenario": "missing.toml"}, ConfigError, "missing.toml"),
        ({"controller": object()}, ConfigError, "controller object: allowed"),
        ({"seed": -1}, ConfigError, "seed -1: allowed"),
        ({"seed": 1.5}, ConfigError, "seed 1.5: allowed"),
        ({"duration": float("nan")}, ConfigError, "^duration nan: allowed"),  # the keyword
        ({"duration": 1e9}, ConfigError, "^duration 1000000000.0: allowed"),
        ({"out": "/proc/no/such"}, ConfigError, ": out folder is not writable"),
        ({"duration": "2"}, ConfigError, "duration '2': allowed"),
        ({"robot": None}, ConfigError, "robot None: allowed"),
        ({"out": 3}, ConfigError, "out 3: allowed"),
    ],
)
def test_bad_input_is_refused_before_anything_rides(
    kwargs, error, words, empty_cwd: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(Simulation, "run", lambda self: pytest.fail("it rode"))
    call = {"robot": "cassie", "board": "none", "controller": "stand", **kwargs}
    with pytest.raises(error, match=words) as caught:
        ridempc.ride(**call)
    assert "\n" not in str(caught.value)
    assert list(empty_cwd.iterdir()) == []


def test_a_controller_object_built_for_another_pair_is_refused(empty_cwd: Path) -> None:
    controller = Hold(load_robot("cassie"), "segway")
    with pytest.raises(ConfigError, match="built for robot 'cassie' on board 'segway'"):
        ridempc.ride("cassie", "none", controller)
    with pytest.raises(ConfigError, match="a dead weight"):
        ridempc.ride("none", "segway", controller)
    assert isinstance(resolve_scenario("stand-still"), Scenario)


_SCRIPT = """
import ridempc
from ridempc.sim.simulation import Simulation
run = Simulation.run
def riding(self):  # says when the ride is running, whatever the machine's load
    print("ready", flush=True)
    return run(self)
Simulation.run = riding
{body}
print("not interrupted")
"""
_RIDE = 'ridempc.ride("cassie", "none", "stand", duration=60.0)'
_CAUGHT = f"""
try:
    {_RIDE}
except KeyboardInterrupt:
    print("caught", flush=True)
    import time; time.sleep(30)  # the process ends at DEADLINE_S all the same
"""


def _interrupted(body: str, signum: int) -> tuple[subprocess.Popen[str], str, str]:
    """A script riding through the API, sent ``signum`` while it rides."""
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    process = subprocess.Popen(
        [sys.executable, "-c", _SCRIPT.format(body=body)], env=env, cwd=ROOT,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert process.stdout is not None and process.stdout.readline() == "ready\n"
    time.sleep(0.5)  # into the ride
    sent = time.monotonic()
    process.send_signal(signum)
    out, err = process.communicate(timeout=30.0)
    assert time.monotonic() - sent < STOP_S
    return process, out, err


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_script_is_interrupted_as_the_command_is(signum: int, code: int) -> None:
    process, out, err = _interrupted(_RIDE, signum)
    assert process.returncode == code and out == ""
    name = signal.Signals(signum).name
    assert err == f"ridempc: interrupted ({name}); no summary returned\n"  # no traceback


def test_a_script_that_catches_the_interrupt_ends_all_the_same() -> None:
    process, out, err = _interrupted(_CAUGHT, signal.SIGINT)
    assert process.returncode == 130 and out == "caught\n"
    assert err == "ridempc: interrupted (SIGINT); no summary returned\n"


_SESSION = """
import os, signal, sys, threading, time
import ridempc
sys.ps1 = ">>> "  # an interactive session, as Python's prompt or a Jupyter kernel
sent = []
def interrupt():
    sent.append(time.monotonic())
    os.kill(os.getpid(), signal.SIGINT)
from ridempc.sim.simulation import Simulation
run = Simulation.run
def riding(self):  # interrupted 2 s into the ride: the MPC's solver thread is solving
    threading.Timer(2.0, interrupt).start()
    return run(self)
Simulation.run = riding
for ride in range(2):  # the session outlives the interrupt and rides again
    sent.clear()
    try:
        ridempc.ride("cassie", "hovershoes", "mpc", duration=60.0)
    except KeyboardInterrupt:
        print(f"caught {time.monotonic() - sent[0]:.3f}", flush=True)
threading.Timer(0.2, interrupt).start()
try:
    time.sleep(10.0)  # Python's own handler is back, not a solver's
except KeyboardInterrupt:
    print(f"plain {time.monotonic() - sent[0]:.3f}", flush=True)
"""


def test_an_interactive_session_outlives_the_interrupt() -> None:
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    done = subprocess.run(
        [sys.executable, "-c", _SESSION], env=env, cwd=ROOT, capture_output=True, text=True,
        timeout=120.0,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    lines = done.stdout.split()
    assert lines[0::2] == ["caught", "caught", "plain"], done.stdout
    assert all(float(lag) < STOP_S for lag in lines[1::2])


def test_the_summary_is_the_one_ridempc_sim_writes(tmp_path: Path, capsys) -> None:
    from ridempc.cli import main

    argv = ["sim", "--robot", "cassie", "--controller", "stand", "--scenario", "push"]
    assert main([*argv, "--duration", str(SHORT), "--seed", "4", "--out", str(tmp_path)]) == 0
    written = json.loads((tmp_path / "summary.json").read_text())
    summary = ridempc.ride("cassie", "none", "stand", "push", duration=SHORT, seed=4)
    timings = {"wall_time_s", "real_time_factor", "controller_update_ms", "files"}
    assert set(summary) == set(written)
    assert {k: v for k, v in summary.items() if k not in timings} == {
        k: v for k, v in written.items() if k not in timings
    }
