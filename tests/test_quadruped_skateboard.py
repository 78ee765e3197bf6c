"""The quadruped's skateboard PD: leg kinematics, the deck from the feet, gains, short rides."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from ridempc.baselines.quadruped_legs import QuadrupedLegs
from ridempc.baselines.quadruped_skateboard import QuadrupedSkateboardPD, _leg_solve
from ridempc.baselines.quadruped_skateboard_gains import (
    DEFAULT_GAINS_FILE,
    load_quadruped_skateboard_gains,
)
from ridempc.baselines.quadruped_support import fit_support_plane, vertical_loads
from ridempc.boards import load_board
from ridempc.errors import ConfigError
from ridempc.robots import load_robot
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.metrics import run_metrics
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation


@pytest.fixture(scope="module")
def dog():
    return load_robot("cyberdog2")


@pytest.fixture(scope="module")
def legs(dog) -> QuadrupedLegs:
    return QuadrupedLegs(
        build_pinocchio_robot(dog), dog.params.contact_sites, tuple(m.joint for m in dog.motors)
    )


def _random_stances(dog, count: int) -> list[np.ndarray]:
    rng = np.random.default_rng(7)
    skate = dog.keyframe_qpos("skate")[7:]
    return [skate + rng.normal(0.0, 0.25, skate.size) for _ in range(count)]


# ---------------------------------------------------------------- kinematics


def test_foot_positions_match_pinocchio(dog, legs) -> None:
    pinocchio = build_pinocchio_robot(dog)
    data = pinocchio.model.createData()
    for q_motors in _random_stances(dog, 5):
        q = pin.neutral(pinocchio.model)
        q[7:] = q_motors
        pin.framesForwardKinematics(pinocchio.model, data, q)
        for leg, foot in zip(legs.legs, legs.positions(q_motors), strict=True):
            expected = data.oMf[pinocchio.frame_id(leg.name)].translation
            np.testing.assert_allclose(foot, expected, atol=1e-12)


def test_leg_jacobian_matches_finite_differences(dog, legs) -> None:
    step = 1e-6
    for q_motors in _random_stances(dog, 5):
        for leg in legs.legs:
            q = q_motors[list(leg.motors)]
            numeric = np.column_stack(
                [
                    (leg.position(q + step * e) - leg.position(q - step * e)) / (2.0 * step)
                    for e in np.eye(3)
                ]
            )
            np.testing.assert_allclose(leg.jacobian(q), numeric, atol=1e-8)


def test_a_straight_legs_force_is_read_without_its_unloaded_direction() -> None:
    """A leg with its knee read exactly straight: its Jacobian is singular (the hip's pitch
    and the knee sweep the foot the same way); the load is read as the least-norm force,
    nothing along the singular direction, rather than ending the ride."""
    reach = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.5]])  # rank 2
    torques = reach @ np.array([2.0, 0.0, 3.0])
    force = _leg_solve(reach, torques)
    np.testing.assert_allclose(reach @ force, torques, atol=1e-12)
    np.testing.assert_allclose(force, [2.0, 1.2, 0.6], atol=1e-12)  # none along (0, 1, -2)
    np.testing.assert_array_equal(_leg_solve(np.eye(3), torques), torques)


def test_inverse_kinematics_inverts_the_forward(dog, legs) -> None:
    skate = dog.keyframe_qpos("skate")[7:]
    for q_motors in _random_stances(dog, 5):
        for leg in legs.legs:
            joints = list(leg.motors)
            q, reachable = leg.inverse(leg.position(q_motors[joints]), skate[joints])
            assert reachable
            np.testing.assert_allclose(q, q_motors[joints], atol=1e-9)


def test_inverse_kinematics_flags_an_unreachable_foot(legs) -> None:
    leg = legs.legs[0]
    _, reachable = leg.inverse(leg.hip + np.array([0.0, 0.1, -1.0]), np.array([0.0, 0.8, -1.3]))
    assert not reachable


# ---------------------------------------------------------------- deck and loads


def test_plane_through_the_feet_gives_the_deck_roll() -> None:
    roll, rate = 0.1, 0.3  # [rad], [rad/s]; positive lowers the -y side
    corners = np.array(
        [[0.17, 0.09, 0.0], [0.17, -0.09, 0.0], [-0.17, 0.09, 0.0], [-0.17, -0.09, 0.0]]
    )
    c, s = math.cos(roll), math.sin(roll)
    rotation = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    feet = corners @ rotation.T
    velocities = np.cross(np.array([rate, 0.0, 0.0]), feet)
    plane = fit_support_plane(feet, velocities)
    assert plane.roll == pytest.approx(roll, abs=1e-12)
    assert plane.pitch == pytest.approx(0.0, abs=1e-12)
    assert plane.roll_rate == pytest.approx(rate, rel=1e-9)
    np.testing.assert_allclose(plane.normal, rotation[:, 2], atol=1e-12)


def test_vertical_loads_put_the_centre_of_pressure_under_the_com() -> None:
    feet = np.array([[0.17, 0.09], [0.17, -0.09], [-0.17, 0.09], [-0.17, -0.09]])
    com = np.array([0.01, -0.04])
    loads = vertical_loads(feet, com, 87.3, 0.0)
    assert loads.sum() == pytest.approx(87.3)
    np.testing.assert_allclose(loads @ feet / loads.sum(), com, atol=1e-12)
    assert vertical_loads(feet, np.array([0.0, -0.2]), 87.3, 2.0).min() == 2.0


# ---------------------------------------------------------------- gains and boards


def test_default_gains_load() -> None:
    gains = load_quadruped_skateboard_gains()
    assert gains.rate_hz == 500.0
    assert gains.roll.max_shift < 0.088  # inside the feet


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("abad = { kp = 80.0, kd = 2.0 }", "abad = { kp = -80.0, kd = 2.0 }", "joints.abad.kp"),
        ("ki = 0.3 ", "ki = 0.3\nkj = 1.0 ", "roll.kj"),
        ("max_shift = 0.06 ", "max_shift = 0.3 ", "roll.max_shift"),
    ],
)
def test_malformed_gains_are_refused_naming_the_field(
    tmp_path: Path, old: str, new: str, field: str
) -> None:
    text = DEFAULT_GAINS_FILE.read_text()
    assert old in text
    bad = tmp_path / "gains.toml"
    bad.write_text(text.replace(old, new, 1))
    with pytest.raises(ConfigError, match=f"field '{field}'"):
        load_quadruped_skateboard_gains(bad)


def test_it_rides_only_a_skateboard_or_flat_ground(dog) -> None:
    with pytest.raises(ConfigError, match="hovershoes"):
        QuadrupedSkateboardPD(dog, "hovershoes")


# ---------------------------------------------------------------- rides


def _ride(dog, board: str, scenario_name: str, duration: float):
    scenario = resolve_scenario(scenario_name, board).with_duration(duration)
    scene = build_scene(
        dog, DEFAULT_PHYSICS_HZ, board=load_board(board), foot_offset=scenario.foot_offset
    )
    controller = QuadrupedSkateboardPD(dog, board)
    result = Simulation(scene, controller, scenario).run()
    return result, run_metrics(result, scenario, dog)


def test_holds_still_on_flat_ground_through_the_pushes(dog) -> None:
    result, _ = _ride(dog, "none", "push", 7.0)
    assert result.status == "ok", result.fall_reason or result.error
    base = result.log["base_position"]
    assert abs(base[-1, 2] - base[0, 2]) < 0.03
    assert np.linalg.norm(base[-1, :2] - base[0, :2]) < 0.1


def test_stands_on_the_skateboard(dog) -> None:
    result, metrics = _ride(dog, "skateboard", "stand-still", 4.0)
    assert result.status == "ok", result.fall_reason or result.error
    assert metrics["board_max_tilt"] < 0.03


def test_tracks_the_deck_roll_reference(dog) -> None:
    result, metrics = _ride(dog, "skateboard", "roll-tracking", 10.0)
    assert result.status == "ok", result.fall_reason or result.error
    # measured 0.016 rad over 2-10 s (0.012 over the full 32 s ride): the start of the wave
    # rings the deck for a second; the bound leaves room for other platforms' arithmetic
    assert metrics["roll_rmse"] < 0.025
    assert metrics["board_max_tilt"] < 0.15


class _WithStandby(QuadrupedSkateboardPD):
    """The PD riding, and a twin fed the same packets only every :data:`STANDBY` ticks, as
    a backup in standby is."""

    STANDBY = 15  # [ticks] the handover's standby divider

    def __init__(self, robot, board: str) -> None:
        super().__init__(robot, board)
        self.twin = QuadrupedSkateboardPD(robot, board)
        self.ticks = 0

    def update(self, sensors, command):
        if self.ticks % self.STANDBY == 0:
            self.twin.update(sensors, command)
        self.ticks += 1
        return super().update(sensors, command)


def test_a_backup_in_standby_keeps_the_rides_time(dog) -> None:
    """Updated every 15th tick, the lateral shift's filters still follow the deck's roll
    reference in time: the twin's shift is the riding PD's, not 15 times slower."""
    scenario = resolve_scenario("roll-tracking", "skateboard").with_duration(2.8)
    scene = build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
    controller = _WithStandby(dog, "skateboard")
    result = Simulation(scene, controller, scenario).run()
    assert result.status == "ok", result.fall_reason or result.error
    riding, standby = controller._shift[0], controller.twin._shift[0]
    assert abs(riding) > 0.005  # [m] the wave has moved the centre of mass
    assert standby == pytest.approx(riding, rel=0.25)


class _InStandby(QuadrupedSkateboardPD):
    """The PD riding, and a twin fed the same packets through :meth:`standby` each tick,
    as a backup is while the MPC rides."""

    def __init__(self, robot, board: str) -> None:
        super().__init__(robot, board)
        self.twin = QuadrupedSkateboardPD(robot, board)

    def update(self, sensors, command):
        self.twin.standby(sensors, command)
        return super().update(sensors, command)


def test_a_backup_in_standby_holds_its_roll_integral(dog) -> None:
    """In standby the roll error is another law's to remove: the twin's integral stays
    where it was (zero from its reset) while the riding PD's integrates the wave's error,
    and the twin's filtered feedback still follows the deck."""
    scenario = resolve_scenario("roll-tracking", "skateboard").with_duration(1.5)
    scene = build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
    controller = _InStandby(dog, "skateboard")
    result = Simulation(scene, controller, scenario).run()
    assert result.status == "ok", result.fall_reason or result.error
    assert abs(controller._roll_integral) > 1e-5  # [m] the riding PD has integrated
    assert controller.twin._roll_integral == 0.0
    assert controller.twin._feedback[0] != 0.0
