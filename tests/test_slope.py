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
from ridempc.mpc.slope import GRAVITY, WINDOW, SlopeEstimator
from ridempc.mpc.state_map import PlanarFrame
from ridempc.robots import load_robot
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation


def _board(position: np.ndarray, speed: float, angle_deg: float, yaw: float = 0.0) -> BoardEstimate:
    a = math.radians(angle_deg)
    velocity = speed * np.array(
        [math.cos(a) * math.cos(yaw), math.cos(a) * math.sin(yaw), math.sin(a)]
    )
    return BoardEstimate(("f",), position.copy(), yaw, 0.0, 0.0, velocity, 0.0)


def _roll(
    slopes: SlopeEstimator, ground: list[tuple[float, float]], speed: float, yaw: float = 0.0
) -> list[float]:
    """Roll one platform at ``speed`` [m/s] (negative: backing) over ``ground``, (seconds,
    slope [deg]) pieces in turn, ticks of 2 ms with a millimetre of noise on its height;
    returns the estimate [deg] after each tick."""
    rng = np.random.default_rng(3)
    position, t, out = np.zeros(3), 0.0, []
    heading = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    for seconds, angle in ground:
        for _ in range(round(seconds / 0.002)):
            a = math.radians(angle)
            position = position + 0.002 * speed * (math.cos(a) * heading + [0, 0, math.sin(a)])
            noisy = position + [0.0, 0.0, 0.001 * rng.standard_normal()]
            t += 0.002
            slopes.update(t, [_board(noisy, speed, angle, yaw)])
            out.append(math.degrees(slopes.angles[0]))
    return out


@pytest.mark.parametrize(("speed", "yaw"), [(0.5, 0.0), (0.5, 1.0), (-0.5, 0.3), (0.05, 0.0)])
def test_the_slope_is_read_off_the_height_lost_over_the_distance_rolled(
    speed: float, yaw: float
) -> None:
    """Ground rising 7 deg ahead (backing: down it), at a walking pace and at 5 cm/s."""
    read = _roll(SlopeEstimator(1), [(0.6 / abs(speed), 7.0)], speed, yaw)
    assert read[-1] == pytest.approx(7.0, abs=0.7)


def test_the_slopes_foot_reads_level_within_a_window_rolled_however_slowly() -> None:
    """Down 13 deg, then level ground crept over at 0.1 m/s: level (within 1 deg) once
    the platform has rolled the window past the foot, 1.5 s, where a speed-gated estimate
    would have held the slope."""
    slow = 0.1  # [m/s]
    read = _roll(SlopeEstimator(1), [(4.0, -13.0), (2.0 * WINDOW / slow, 0.0)], slow)
    at_foot = round(4.0 / 0.002)
    assert read[at_foot - 1] == pytest.approx(-13.0, abs=1.0)
    past = at_foot + round(1.05 * WINDOW / slow / 0.002)
    assert max(abs(r) for r in read[past:]) < 1.0


def test_steps_and_standing_still_leave_the_slope_alone() -> None:
    """A drop of 3.5 cm off a step's edge (at 0.7 m/s down, 80 deg) between level
    ground: the estimate never reads the drop; standing still, it holds what it read."""
    slopes = SlopeEstimator(1)
    read = _roll(slopes, [(1.0, 0.0)], 0.5)
    position = np.zeros(3)
    for k in range(25):  # the fall: 3.5 cm in 50 ms
        position = position + [0.001, 0.0, -0.0014]
        slopes.update(1.0 + 0.002 * k, [_board(position, 0.71, -80.0)])
        read.append(math.degrees(slopes.angles[0]))
    read += _roll(slopes, [(1.0, 0.0)], 0.5)
    assert max(abs(r) for r in read) < 1.0
    slopes.angles[0] = before = math.radians(7.0)  # as if it had stood on 7 deg
    last = slopes._last[0]
    assert last is not None
    for k in range(200):  # standing, the sensors bobbing by a millimetre
        bob = np.array(last) + [0.0, 0.0, 0.001 * math.sin(0.3 * k)]
        slopes.update(3.0 + 0.002 * k, [_board(bob, 0.0, 0.0)])
    assert slopes.angles[0] == before
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
