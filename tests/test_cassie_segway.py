"""Cassie on the Segway (``pd``, Segway paper IV-B): gain file, outer loops, and short rides.

The rides are short versions of the library's scenarios; the bounds come from measured runs
(``ridempc sim --robot cassie --board segway --controller pd``) with some margin.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from ridempc.baselines.cassie_segway import CassieSegway, ShiftLoop
from ridempc.baselines.cassie_segway_gains import (
    DEFAULT_GAINS_FILE,
    LoopGains,
    load_segway_gains,
)
from ridempc.baselines.cassie_standing_gains import load_standing_gains
from ridempc.boards import load_board
from ridempc.controllers import make_controller
from ridempc.robots import load_robot
from ridempc.scenarios.scenario import Scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import RunResult, Simulation
from tests.helpers import assert_gain_edit_refused

PAD = "board/knee_pad"


@pytest.fixture(scope="module")
def cassie():
    return load_robot("cassie")


def _loop(**changes: float) -> ShiftLoop:
    fields = dict(
        feedforward=0.0,
        feedforward_rate=0.0,
        kp=0.1,
        ki=0.0,
        integral_limit=0.05,
        max_shift=0.05,
        max_rate=1.0,
        filter_hz=0.0,
    )
    fields.update(changes)
    return ShiftLoop(LoopGains(**fields))


def _ride(robot, scenario: Scenario) -> tuple[RunResult, Simulation]:
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, board=load_board("segway"))
    simulation = Simulation(scene, make_controller("pd", robot, "segway"), scenario)
    return simulation.run(), simulation


def _pad_clearance(simulation: Simulation) -> dict[str, float]:
    """Distance from the knee pad to each upper shin [m] (negative: overlapping)."""
    model, data = simulation.scene.model, simulation.scene.data
    pad = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, PAD)
    out = {}
    for side in ("left", "right"):
        shin = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{side}_shin_upper")
        out[side] = float(mujoco.mj_geomDistance(model, data, pad, shin, 0.2, None))
    return out


# ---------------------------------------------------------------- gain file


def test_gains_lay_the_segway_changes_over_the_standing_gains() -> None:
    gains = load_segway_gains()
    standing = load_standing_gains()
    assert gains.standing.posture.leg_length == pytest.approx(0.62)  # crouched (Fig. 7)
    assert gains.standing.com_x.kp < standing.com_x.kp  # the feet's gains turned down
    assert gains.standing.com_x.kd < standing.com_x.kd
    assert gains.standing.joints.toe.kd < standing.joints.toe.kd
    assert gains.standing.roll == standing.roll  # what the file leaves out is the standing one


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("kp = 0.2               # [m per m/s]", "kp = -0.2", "velocity.kp"),
        ("max_shift = 0.1        # [m]", "max_shift = 0.5", "turning.max_shift"),
        (
            "com_x = { kp = 1.5, kd = 0.6 }",
            'com_x = { kp = "soft", kd = 0.6 }',
            "standing.com_x.kp",
        ),
        ("filter_hz = 2.0", "filter_hz = 2.0\nfiltre_hz = 1.0", "velocity.filtre_hz"),
    ],
)
def test_bad_gain_file_is_refused_naming_the_field(cassie, tmp_path, old, new, field) -> None:
    def build(path):
        return CassieSegway(cassie, gains=path)

    assert_gain_edit_refused(DEFAULT_GAINS_FILE, tmp_path, old, new, field, build)


def test_pd_on_the_segway_is_the_segway_rider(cassie) -> None:
    controller = make_controller("pd", cassie, "segway")
    assert isinstance(controller, CassieSegway)
    assert not controller.uses_ground_truth
    assert controller.estimate() is None  # until its first tick


# ---------------------------------------------------------------- outer loop


def test_shift_loop_is_proportional_then_bounded() -> None:
    loop = _loop(kp=0.1, max_shift=0.05)
    assert loop(0.0, 1.0, 0.8) == 0.0  # starts from rest: the slew allows nothing at once
    assert loop(1.0, 1.0, 0.8) == pytest.approx(0.02)  # 0.1 m per unit of error
    assert loop(2.0, 1.0, 0.0) == pytest.approx(0.05)  # clamped
    assert loop(3.0, -1.0, 0.0) == pytest.approx(-0.05)


def test_shift_loop_is_slewed() -> None:
    loop = _loop(kp=1.0, max_shift=0.05, max_rate=0.01)
    loop(0.0, 0.0, 0.0)
    assert loop(1.0, 1.0, 0.0) == pytest.approx(0.01)  # at most 0.01 m/s
    assert loop(2.0, 1.0, 0.0) == pytest.approx(0.02)


def test_shift_loop_integral_stops_while_saturated() -> None:
    loop = _loop(kp=0.0, ki=0.01, integral_limit=1.0, max_shift=0.05)
    for k in range(101):  # error 1 for 100 s: 1 m unbounded, held at the 0.05 m bound
        shift = loop(float(k), 1.0, 0.0)
    assert shift == pytest.approx(0.05)
    recovered = [loop(100.0 + k * 0.1, 0.0, 1.0) for k in range(1, 11)]  # error -1 for 1 s
    assert recovered[-1] == pytest.approx(0.05 - 0.01, abs=2e-3)  # leaves the bound at once


def test_shift_loop_feeds_the_command_and_its_rate_forward() -> None:
    loop = _loop(kp=0.0, feedforward=0.02, feedforward_rate=0.1, max_shift=0.12)
    loop(0.0, 0.0, 0.0)
    shift = loop(0.5, 0.5, 0.5)  # a ramp of 1 per second, tracked exactly
    assert shift == pytest.approx(0.02 * 0.5 + 0.1 * 1.0)


# ---------------------------------------------------------------- short rides


def test_crouches_with_the_knees_beside_the_pad(cassie) -> None:
    """Standing still: the crouch lowers the base by about 0.28 m and leaves each upper shin
    a few millimetres off the knee pad (measured 3-4 mm), neither clamping it nor far."""
    result, simulation = _ride(cassie, Scenario(name="still", duration=5.0))
    assert result.status == "ok", result.fall_reason or result.error
    log = result.log
    assert log["base_position"][0, 2] - log["base_position"][-1, 2] > 0.2
    settled = log["time"] >= 3.5
    assert np.max(np.abs(log["forward_velocity"][settled])) < 0.1
    assert np.max(np.abs(log["yaw_rate"][settled])) < 0.05
    for side, gap in _pad_clearance(simulation).items():
        assert 0.0 <= gap < 0.015, side
    assert isinstance(simulation.controller, CassieSegway)
    estimate = simulation.controller.estimate()
    assert estimate is not None and estimate.board is not None


def test_rides_at_1_m_s_and_turns_left_on_command(cassie) -> None:
    """1 m/s from 2.5 s (1 s ramp), then 0.5 rad/s to the left from 5.5 s. Measured: the
    speed within 0.05 m/s of 1 m/s from 4.5 s, the yaw rate 0.42-0.51 rad/s from 7.5 s."""
    scenario = Scenario(
        name="ride-and-turn",
        duration=9.0,
        commands=[
            dict(t=0.0, velocity=0.0, yaw_rate=0.0),
            dict(t=2.5, velocity=1.0, ramp=1.0),
            dict(t=5.5, yaw_rate=0.5),
        ],
    )
    result, _ = _ride(cassie, scenario)
    assert result.status == "ok", result.fall_reason or result.error
    log = result.log
    time = log["time"]
    riding = time >= 4.5
    assert np.max(np.abs(log["forward_velocity"][riding] - 1.0)) < 0.12
    turning = time >= 7.5
    assert abs(np.mean(log["yaw_rate"][turning]) - 0.5) < 0.08
    assert np.min(log["yaw_rate"][turning]) > 0.3
    assert np.max(np.abs(log["yaw_rate"][(time >= 2.0) & (time < 5.5)])) < 0.05
