"""The MPC rider's crouch and lean loop on the Segway (``ridempc.mpc.lean``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.mpc.lean import (
    CROUCH_DELAY,
    CROUCH_SECONDS,
    LEAN_GAINS,
    STANDING_PULL,
    Crouch,
    LeanSteering,
    com_height,
)
from ridempc.mpc.rider import MpcRider
from ridempc.mpc.riding_posture import ride_qpos
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
    ride = ride_qpos(cassie, "segway")
    assert com_height(cassie, ride) == pytest.approx(0.617, abs=0.005)
    crouch = Crouch.of(cassie, "segway")
    assert crouch is not None and crouch.drop == pytest.approx(-0.255, abs=0.005)
    assert Crouch.of(cassie, "hovershoes") is None
    np.testing.assert_array_equal(ride_qpos(cassie, "hovershoes"), cassie.stance_qpos("hovershoes"))


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


def test_standing_the_lean_grows_against_the_turn_and_moves_the_balance_along(
    segway_rider, problem
) -> None:
    """Standing, a left turn commanded and a fast right one measured: the loop holds the yaw
    rate at zero, so the offset is positive (to the left), grows while the error lasts,
    stays within the standing pull x max_shift, and moves the reference's balance
    (forces) with it at every node; with no offset the problem is untouched."""
    steering = LeanSteering()
    names = segway_rider.layout.names
    side, rate = names["com_y"], names["vy"]
    assert steering.lean(problem, side, rate, None) is problem
    slow = 0.5 * steering.min_speed
    offsets = [steering.update(0.1 * k, 0.5, -1.0, slow) for k in range(200)]
    assert not steering.riding and steering.turn_rate == 0.0
    assert offsets[1] > 0.0 and offsets[50] > offsets[5]
    bound = STANDING_PULL * LEAN_GAINS.max_shift
    assert max(offsets) <= bound + 1e-12 and offsets[-1] == pytest.approx(bound)
    nx, nu = problem.state_reference.shape[1], problem.input_reference.shape[1]
    other = names["pelvis_roll"]
    balance = StaticShift(
        states=np.eye(nx)[side] + 0.5 * np.eye(nx)[other],
        inputs=np.full(nu, 100.0),
        velocities=np.zeros(nx),
    )
    states, inputs = problem.state_reference, problem.input_reference
    moved = steering.lean(problem, side, rate, balance)
    np.testing.assert_allclose(moved.state_reference[:, side], states[:, side] + bound)
    np.testing.assert_allclose(moved.state_reference[:, other], states[:, other] + 0.5 * bound)
    np.testing.assert_allclose(moved.state_reference[:, rate], states[:, rate])
    np.testing.assert_allclose(moved.input_reference, inputs + 100.0 * bound)
    assert steering.turn(problem, segway_rider.layout) is problem  # standing: no turn laid on
    assert steering.drift(nx, rate, 0.2, 0.3) is None
    still = LeanSteering()  # standing still, nothing turning: nothing leans
    assert still.update(0.1, 0.5, 0.0, slow) == 0.0
    with pytest.raises(ValueError, match="pull"):
        LeanSteering(standing_pull=0.0)
    with pytest.raises(ValueError, match="time constant"):
        LeanSteering(seconds=0.0)


def test_riding_the_lean_is_a_path_from_the_centre_of_mass(segway_rider, problem) -> None:
    """Riding, the offset is the loop's shift itself (the feedforward's 0.08 m per rad/s
    at the first tick, slewed), and the reference's CoM y runs from the initial state's
    offset to it as :math:`s + (y_0 - s) e^{-k \\Delta t / T}`, its :math:`\\dot y` the
    path's rate, which the path integrates (trapezoids, to within a millimetre)."""
    steering = LeanSteering()
    names = segway_rider.layout.names
    side, rate = names["com_y"], names["vy"]
    first = steering.update(0.0, 0.5, 0.0, 1.0)
    assert steering.riding and steering.turn_rate == 0.5
    assert first == 0.0  # the slew starts from zero
    offset = steering.update(0.2, 0.5, 0.0, 1.0)
    assert offset == pytest.approx(LEAN_GAINS.max_rate * 0.2)  # slewed towards 0.04+ m
    x0 = problem.initial_state.copy()
    x0[side] = problem.state_reference[0, side] - 0.03  # the CoM 3 cm right of the line
    moved = steering.lean(replace(problem, initial_state=x0), side, rate, None)
    path = moved.state_reference[:, side] - problem.state_reference[:, side]
    k = np.arange(len(path))
    expected = offset + (-0.03 - offset) * np.exp(-k * problem.dt / steering.seconds)
    np.testing.assert_allclose(path, expected)
    assert path[0] == pytest.approx(-0.03) and abs(path[-1] - offset) < abs(path[1] - offset)
    speed = moved.state_reference[:, rate] - problem.state_reference[:, rate]
    assert speed[0] == pytest.approx((offset + 0.03) / steering.seconds)
    steps = 0.5 * (speed[1:] + speed[:-1]) * problem.dt
    np.testing.assert_allclose(np.diff(path), steps, atol=1e-3)


def test_riding_the_turn_is_laid_on_the_yaw_references_and_its_pull_on_the_rates(
    segway_rider, problem
) -> None:
    """Riding at 0.5 rad/s: every heading of the reference turns by 0.5 k dt and every
    yaw rate gains 0.5 rad/s, nothing else moves; the drift is the centrifugal
    acceleration :math:`-v \\hat\\omega` on the CoM's :math:`\\dot y` alone."""
    steering = LeanSteering()
    names = segway_rider.layout.names
    steering.update(0.0, 0.5, 0.0, 1.0)
    turned = steering.turn(problem, segway_rider.layout)
    before, after = problem.state_reference, turned.state_reference
    k = np.arange(before.shape[0])
    headings = [names["pelvis_yaw"], names["segway_psi"]]
    rates = [names["wz"], names["segway_yaw_rate"]]
    for heading in headings:
        np.testing.assert_allclose(after[:, heading] - before[:, heading], 0.5 * k * problem.dt)
    np.testing.assert_allclose(after[:, rates] - before[:, rates], 0.5)
    others = [i for i in range(before.shape[1]) if i not in headings + rates]
    np.testing.assert_array_equal(after[:, others], before[:, others])
    nx = before.shape[1]
    drift = steering.drift(nx, names["vy"], 2.0, 0.4)
    assert drift is not None
    np.testing.assert_allclose(drift, -0.8 * np.eye(nx)[names["vy"]])
    straight = LeanSteering()
    straight.update(0.0, 0.0, 0.0, 1.0)
    assert straight.turn(problem, segway_rider.layout) is problem


def test_on_the_segway_cassie_crouches_and_turns_by_the_knee_bar(cassie, tmp_path) -> None:
    """Riding at 1 m/s, 0.5 rad/s commanded from 6 s: the rider has crouched (pelvis about
    0.25 m lower), leans into the knee bar and the Segway turns; only the Segway pair leans."""
    rider = MpcRider(cassie, "segway")  # its own: the ride changes the lean loop
    assert rider.lean is not None and MpcRider(cassie, "hovershoes").lean is None
    np.testing.assert_allclose(
        rider.wbc.posture, motor_posture(rider.pinocchio, cassie, ride_qpos(cassie, "segway"))
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


def test_the_segway_rider_follows_the_grounds_rate_slowly(segway_rider) -> None:
    """The pair file's ``ground_rate_filter`` reaches the rider's state map (1 s: the
    firmware's pitch swing kept out of the rider's vertical rate up a slope)."""
    assert segway_rider.map.ground_rate_filter == 1.0
