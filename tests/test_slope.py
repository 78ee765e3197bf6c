"""The slope under each platform and the ground the MPC's frame follows, from sensors only."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.estimation import EstimatedState
from ridempc.estimation.state import BoardEstimate
from ridempc.mpc.rider import MpcRider
from ridempc.mpc.slope import GRAVITY, SlopeEstimator
from ridempc.mpc.state_map import PlanarFrame
from ridempc.robots import load_robot
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation


def _board(speed: float, angle_deg: float, yaw: float = 0.0, z: float = 0.0) -> BoardEstimate:
    a = math.radians(angle_deg)
    velocity = speed * np.array(
        [math.cos(a) * math.cos(yaw), math.cos(a) * math.sin(yaw), math.sin(a)]
    )
    return BoardEstimate(("f",), np.array([0.0, 0.0, z]), yaw, 0.0, 0.0, velocity, 0.0)


@pytest.mark.parametrize(("speed", "yaw"), [(0.5, 0.0), (0.5, 1.0), (-0.5, 0.3)])
def test_the_slope_is_read_off_the_platforms_velocity(speed: float, yaw: float) -> None:
    slopes = SlopeEstimator(1)
    for k in range(200):  # 2 s at 100 Hz on ground rising 7 deg ahead (backing: down it)
        slopes.update(0.01 * k, [_board(speed, 7.0, yaw)])
    assert math.degrees(slopes.angles[0]) == pytest.approx(7.0, abs=0.05)


def test_steps_and_standing_still_leave_the_slope_alone() -> None:
    slopes = SlopeEstimator(1)
    slopes.update(0.0, [_board(0.5, 0.0)])
    slopes.update(0.1, [_board(0.6, -60.0)])  # dropping off a step
    slopes.update(0.2, [_board(0.05, 45.0)])  # standing: the direction is noise
    assert slopes.angles == [0.0]
    drag = SlopeEstimator.gravity_drag(math.radians(7.0), 2.7, 170.0)
    assert drag == pytest.approx(-(2.7 * GRAVITY + 170.0) * math.sin(math.radians(7.0)))


def test_the_library_frame_carries_the_grounds_height() -> None:
    frame = PlanarFrame.through(0.5, (1.0, 0.0), (3.0, 2.0), height=-0.1)
    p = np.array([0.3, -0.2, 0.8])
    assert frame.point_to_world(frame.point_to_library(p)) == pytest.approx(p)
    assert frame.point_to_library(np.array([3.0, 2.0, -0.1])) == pytest.approx([1.0, 0.0, 0.0])


def _standing_dog() -> tuple[MpcRider, EstimatedState]:
    """The dog's MPC rider after a tenth of a second standing on the skateboard, and its
    estimate."""
    dog = load_robot("cyberdog2")
    scenario = resolve_scenario("stand-still", "skateboard").with_duration(0.1)
    scene = build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
    rider = MpcRider(dog, "skateboard")
    Simulation(scene, rider, scenario).run()
    estimate = rider.estimator.state
    assert estimate is not None and estimate.boards
    return rider, estimate


def test_the_mpc_frame_follows_the_ground_under_the_platforms() -> None:
    """Platforms 0.1 m lower than where they started: the library frame sinks with them,
    so the rider's centre of mass keeps its height over them in the MPC's state."""
    rider, estimate = _standing_dog()
    n, state_map = rider.layout.names, rider.map
    state_map.reset()  # the platforms' first height: where the estimate has them now
    later = replace(estimate, time=estimate.time + 1.0)  # ten filter time constants later
    level = state_map.follow_ground(later)
    before = state_map.state(estimate)
    lowered = replace(
        estimate,
        time=estimate.time + 2.0,
        boards=tuple(
            replace(b, position=b.position - np.array([0.0, 0.0, 0.1])) for b in estimate.boards
        ),
    )
    assert state_map.follow_ground(lowered) - level == pytest.approx(-0.1, abs=1e-3)
    after = state_map.state(estimate)
    assert after[n["com_z"]] - before[n["com_z"]] == pytest.approx(0.1, abs=1e-3)


@pytest.mark.parametrize(("feet_each", "followed"), [(None, 0.0), (1, 0.02)])
def test_a_rise_within_the_band_is_followed_only_under_single_feet(
    feet_each: int | None, followed: float
) -> None:
    """A 2 cm rise: within the band for the dog's four-footed deck (a foot off it moves its
    estimate that much), followed at once when each platform carries one foot."""
    rider, estimate = _standing_dog()
    if feet_each is not None:
        boards = tuple(replace(b, feet=b.feet[:feet_each]) for b in estimate.boards)
        estimate = replace(estimate, boards=boards)
    state_map = rider.map
    state_map.reset()
    level = state_map.follow_ground(replace(estimate, time=estimate.time + 1.0))
    raised = replace(
        estimate,
        time=estimate.time + 2.0,
        boards=tuple(
            replace(b, position=b.position + np.array([0.0, 0.0, 0.02])) for b in estimate.boards
        ),
    )
    assert state_map.follow_ground(raised) - level == pytest.approx(followed, abs=1e-3)
