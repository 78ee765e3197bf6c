"""The MPC rider's crouch and lean loop on the Segway (``ridempc.mpc.lean``)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.mpc.lean import (
    CROUCH_DELAY,
    CROUCH_SECONDS,
    LEAN_GAINS,
    Crouch,
    LeanSteering,
    com_height,
)
from ridempc.mpc.rider import MpcRider
from ridempc.mpc.statics import StaticShift
from ridempc.robots import load_robot
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from ridempc.wbc.controller import motor_posture


@pytest.fixture(scope="module")
def cassie():
    return load_robot("cassie")


@pytest.fixture(scope="module")
def segway_rider(cassie):
    return MpcRider(cassie, "segway")


@pytest.fixture(scope="module")
def problem(segway_rider):
    """A Segway MPC problem at the library's start, planned from the reference itself."""
    mpc = segway_rider.mpc
    return mpc.problem(0.0, mpc.reference.states_at(np.array([0.0]))[0])


def test_the_riding_keyframe_crouches_cassie_by_a_quarter_metre(cassie) -> None:
    """The Segway's riding keyframe stands on its soles with the centre of mass 0.617 m
    over them (the pd rider's crouch), 0.255 m under the stance's; elsewhere the rider
    rides in its stance."""
    ride = cassie.ride_qpos("segway")
    assert com_height(cassie, ride) == pytest.approx(0.617, abs=0.005)
    crouch = Crouch.of(cassie, "segway")
    assert crouch is not None and crouch.drop == pytest.approx(-0.255, abs=0.005)
    assert Crouch.of(cassie, "hovershoes") is None
    np.testing.assert_array_equal(cassie.ride_qpos("hovershoes"), cassie.stance_qpos("hovershoes"))


def test_the_crouch_comes_in_over_its_ramp(segway_rider, problem) -> None:
    crouch = Crouch(-0.2)
    height = segway_rider.layout.names["com_z"]
    start = 10.0
    before = problem.state_reference
    assert crouch.lower(problem, height, start) is problem  # the ride's first tick: not yet
    half = crouch.lower(problem, height, start + CROUCH_DELAY + 0.5 * CROUCH_SECONDS)
    np.testing.assert_allclose(half.state_reference[:, height], before[:, height] - 0.1)
    full = crouch.lower(problem, height, start + CROUCH_DELAY + 2.0 * CROUCH_SECONDS)
    np.testing.assert_allclose(full.state_reference[:, height], before[:, height] - 0.2)
    others = np.arange(before.shape[1]) != height
    np.testing.assert_array_equal(full.state_reference[:, others], before[:, others])
    with pytest.raises(ValueError, match="height"):
        Crouch(float("nan"))


def test_the_lean_grows_towards_the_turn_and_moves_the_balance_along(segway_rider, problem) -> None:
    """A left turn commanded and none measured: the offset is positive (to the left),
    grows while the error lasts, stays within pull x max_shift, and moves the reference's
    balance (forces) with it; with no offset the problem is untouched."""
    steering = LeanSteering()
    side = segway_rider.layout.names["com_y"]
    assert steering.lean(problem, side, None) is problem
    offsets = [steering.update(0.1 * k, 0.5, 0.0, 1.0) for k in range(200)]
    assert offsets[1] > 0.0 and offsets[50] > offsets[5]
    bound = steering.pull * LEAN_GAINS.max_shift
    assert max(offsets) <= bound + 1e-12 and offsets[-1] == pytest.approx(bound)
    nx, nu = problem.state_reference.shape[1], problem.input_reference.shape[1]
    other = segway_rider.layout.names["pelvis_roll"]
    balance = StaticShift(
        states=np.eye(nx)[side] + 0.5 * np.eye(nx)[other],
        inputs=np.full(nu, 100.0),
        velocities=np.zeros(nx),
    )
    states, inputs = problem.state_reference, problem.input_reference
    moved = steering.lean(problem, side, balance)
    np.testing.assert_allclose(moved.state_reference[:, side], states[:, side] + bound)
    np.testing.assert_allclose(moved.state_reference[:, other], states[:, other] + 0.5 * bound)
    np.testing.assert_allclose(moved.input_reference, inputs + 100.0 * bound)
    slow = LeanSteering()  # too slow to turn: holds the yaw rate at zero
    assert slow.update(0.1, 0.5, 0.0, 0.5 * slow.min_speed) == 0.0
    assert slow.update(0.2, 0.5, -0.2, 0.5 * slow.min_speed) > 0.0  # turning right: leans left
    with pytest.raises(ValueError, match="pull"):
        LeanSteering(pull=0.0)


def test_on_the_segway_cassie_crouches_and_turns_by_the_knee_bar(cassie, tmp_path) -> None:
    """Riding at 1 m/s, 0.5 rad/s commanded from 6 s: the rider has crouched (pelvis about
    0.25 m lower), leans into the knee bar and the Segway turns; only the Segway pair leans."""
    rider = MpcRider(cassie, "segway")  # its own: the ride changes the lean loop
    assert rider.lean is not None and MpcRider(cassie, "hovershoes").lean is None
    np.testing.assert_allclose(
        rider.wbc.posture, motor_posture(rider.pinocchio, cassie, cassie.ride_qpos("segway"))
    )
    toml = tmp_path / "turn.toml"
    toml.write_text(
        'name = "turn"\ndescription = "a turn at 1 m/s"\nduration = 9.0\n'
        "[[commands]]\nt = 0.0\nvelocity = 0.0\nyaw_rate = 0.0\n"
        "[[commands]]\nt = 0.5\nvelocity = 1.0\nramp = 1.5\n"
        "[[commands]]\nt = 6.0\nyaw_rate = 0.5\n"
    )
    scenario = resolve_scenario(str(toml), "segway")
    scene = build_scene(cassie, DEFAULT_PHYSICS_HZ, board=load_board("segway"))
    result = Simulation(scene, rider, scenario).run()
    assert result.status == "ok", result.fall_reason
    log = result.log
    time = log["time"]
    height = log["base_position"][:, 2]
    assert height[0] - height[time > 4.0].mean() > 0.2  # [m] crouched
    before, turning = (time > 4.0) & (time < 6.0), time > 7.5
    assert np.abs(log["yaw_rate"][before]).max() < 0.15  # [rad/s] straight before the command
    assert log["yaw_rate"][turning].mean() > 0.35, log["yaw_rate"][turning].mean()  # [rad/s]
    assert log["firmware_knee_bar"][turning].mean() > 0.02  # [rad] the shins push the bar
