"""The Go1 on the skateboard from data only: its pair file, its motion library and its PD
gains file load, and both controllers ride the start of a push-off (1.5 s, seed 0)."""

from __future__ import annotations

import pytest

import ridempc
from ridempc.baselines.quadruped_skateboard_gains import (
    DEFAULT_GAINS_FILE,
    gains_file,
    load_quadruped_skateboard_gains,
)
from ridempc.library.store import library_folder, load_library
from ridempc.mpc.pairs import load_mpc_pair

SHORT = 1.5  # [s] the first push's lift-off and stroke (the command comes at 0.5 s)


def test_the_go1_pair_loads_with_its_library() -> None:
    pair = load_mpc_pair("go1", "skateboard")
    assert pair is not None
    manifest, _ = load_library(library_folder("go1", "skateboard"))
    assert manifest.robot == "go1"
    assert {e.target for e in manifest.entries if e.kind == "accelerate"} >= {0.3, 0.5, 0.7, 1.0}


def test_each_quadruped_has_its_pd_gains() -> None:
    """The CyberDog2 keeps the shared file; the Go1's pair file names its own, scaled by its
    12.74 kg; on flat ground, without a pair file, the shared one."""
    assert gains_file("cyberdog2", "skateboard") == DEFAULT_GAINS_FILE
    assert gains_file("go1", "skateboard").name == "quadruped_skateboard.go1.toml"
    assert gains_file("go1", "none") == DEFAULT_GAINS_FILE
    dog = load_quadruped_skateboard_gains(gains_file("cyberdog2", "skateboard"))
    go1 = load_quadruped_skateboard_gains(gains_file("go1", "skateboard"))
    assert dog.roll.feedforward == 0.85 and go1.roll.feedforward == 0.79
    assert go1.joints.knee.kp == 100.0  # robots/go1/robot.toml's joint PD


@pytest.mark.parametrize("controller", ["mpc", "pd"])
def test_the_go1_rides_the_start_of_a_push_off(controller: str) -> None:
    summary = ridempc.ride("go1", "skateboard", controller, "push-off-0.5", duration=SHORT)
    assert summary["status"] == "ok" and not summary["fell"]
