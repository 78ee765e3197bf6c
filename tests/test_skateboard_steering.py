"""Steering the skateboard by its deck roll: eq. (14) inverted, its limits, and the roll it
asks for turning the simulated board at the commanded rate."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.boards.skateboard.experiments import (
    RollHold,
    SteeringTrial,
    run_steering_trial,
    skateboard_scene,
)
from ridempc.boards.skateboard.reduced import yaw_rate
from ridempc.boards.skateboard.steering import MIN_SPEED, STANCE_ROLL, RollSteering
from ridempc.errors import ConfigError

DEAD_WEIGHT = 8.9  # [kg] CyberDog2


@pytest.fixture(scope="module")
def steering() -> RollSteering:
    board = load_board("skateboard")
    assert board is not None
    return RollSteering.of(board.params)  # type: ignore[arg-type]


@pytest.mark.parametrize("speed", [0.4, 0.7, 1.5])
@pytest.mark.parametrize("wanted", [-0.2, 0.05, 0.2])
def test_roll_inverts_eq_14(steering: RollSteering, speed: float, wanted: float) -> None:
    roll = steering.roll(wanted, speed)
    assert abs(roll) <= STANCE_ROLL
    assert yaw_rate(speed, roll, steering.gain) == pytest.approx(wanted, rel=1e-9)
    assert np.sign(roll) == -np.sign(wanted)  # turning left (positive) leans left


def test_roll_limits(steering: RollSteering) -> None:
    assert steering.roll(0.2, 0.5 * MIN_SPEED) == 0.0  # not rolling: no steering
    assert steering.roll(5.0, 0.7) == pytest.approx(-STANCE_ROLL)  # held within the stance
    assert steering.max_yaw_rate(0.7) == pytest.approx(0.7 * steering.gain * math.sin(STANCE_ROLL))
    # a circle asks for the same roll at every speed: K / R
    radius = 3.0
    for speed in (0.5, 1.0):
        assert math.sin(-steering.roll(speed / radius, speed)) == pytest.approx(
            1.0 / (steering.gain * radius)
        )
    assert steering.min_radius == pytest.approx(1.0 / (steering.gain * math.sin(STANCE_ROLL)))


@pytest.mark.parametrize(
    ("yaw", "speed", "says"),
    [(0.2, 0.1, "|velocity| >= 0.3"), (0.6, 0.7, "|yaw_rate| <= 0.40")],
)
def test_bad_steering_commands_name_the_field(
    steering: RollSteering, yaw: float, speed: float, says: str
) -> None:
    with pytest.raises(ConfigError, match=r"commands\.2\.yaw_rate") as caught:
        steering.check_command(yaw, speed, "scenario 'x': commands.2.yaw_rate")
    assert says in str(caught.value)
    assert "\n" not in str(caught.value)
    steering.check_command(0.0, 0.0, "fine")  # no turn: any speed
    steering.check_command(0.2, 0.7, "fine")
    with pytest.raises(ConfigError, match="radius 1 m"):
        steering.check_radius(1.0, "path.radius")


def test_the_commanded_roll_turns_the_simulated_board(steering: RollSteering) -> None:
    """The bare board under a dead weight, pushed to 0.7 m/s and held at the roll the map
    asks for 0.2 rad/s: MuJoCo's trucks turn it at that rate (within 10 %)."""
    board = load_board("skateboard")
    scene = skateboard_scene(board, DEAD_WEIGHT)
    speed, wanted = 0.7, 0.2
    roll = steering.roll(wanted, speed)
    record = run_steering_trial(
        scene, SteeringTrial("steer", speed, RollHold(0.8, roll), duration=2.5)
    ).window(1.8)
    assert np.mean(record.roll) == pytest.approx(roll, rel=0.1)
    assert float(np.mean(record.yaw_rate)) == pytest.approx(wanted, rel=0.1)


def test_the_mpc_rider_steers_a_planned_yaw_rate_by_the_deck_roll() -> None:
    """A yaw-rate command reaches the skateboard's MPC as the deck roll that steers it, read
    ahead over the horizon as the commanded roll is; that roll's turn (eq. 14) is the
    commanded yaw rate; at rest nothing is steered."""
    from ridempc.mpc.rider import MpcRider
    from ridempc.robots import load_robot
    from ridempc.scenarios import resolve_scenario
    from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
    from ridempc.sim.scene import build_scene
    from ridempc.sim.simulation import Simulation

    dog = load_robot("cyberdog2")
    rider = MpcRider(dog, "skateboard")
    scenario = resolve_scenario("yaw-steps", "skateboard")
    Simulation(
        build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard")), rider, scenario
    )
    settings, lead = rider.mpc.settings, rider.pair.roll_lead
    now, speed = 7.6, 0.7  # the +0.2 rad/s step turns to -0.2 at 7.7 s
    times = now + lead + settings.dt * np.arange(settings.horizon + 1)
    wanted = np.array([scenario.command_at(float(t)).yaw_rate for t in times])
    assert wanted[0] == 0.2 and wanted[-1] < -0.15  # ramped over 0.4 s from 7.7 s
    roll = rider.commands.steering_roll(scenario.command_at(now), now, speed)
    assert rider.commands.roll_steering is not None
    np.testing.assert_allclose(yaw_rate(speed, roll, rider.commands.roll_steering.gain), wanted)
    turn = rider.commands.roll_turn(roll, speed, rider.layout.names)
    np.testing.assert_allclose(turn, wanted[: settings.horizon])
    assert not rider.commands.steering_roll(scenario.command_at(now), now, 0.1).any()
