"""The ``stand`` controller keeps each robot up on flat ground, and survives the push scenario."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.controllers import make_controller
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation


def _tilt(quaternions: np.ndarray) -> np.ndarray:
    """Angle between the base's z axis and the world's [rad]."""
    w, x, y, z = quaternions.T
    return np.arccos(np.clip(1.0 - 2.0 * (x**2 + y**2), -1.0, 1.0))


@pytest.mark.parametrize("name", ["stand-still", "push"])
def test_stand_keeps_the_robot_up(robot, name: str) -> None:
    scenario = resolve_scenario(name)
    if name == "stand-still":
        scenario = scenario.with_duration(3.0)
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ)
    result = Simulation(scene, make_controller("stand", robot), scenario).run()
    log = result.log
    assert result.status == "ok", result.fall_reason or result.error
    assert result.sim_time == pytest.approx(scenario.duration)
    height = log["base_position"][:, 2]
    assert abs(height[-1] - height[0]) < 0.03  # settles by millimetres, does not sag
    assert np.max(_tilt(log["base_quaternion"])) < np.radians(10.0)
    assert np.linalg.norm(log["base_position"][-1, :2] - log["base_position"][0, :2]) < 0.1


def test_parameter_changes_apply_and_are_undone(robot) -> None:
    from tests.helpers import scenario

    scene = build_scene(robot, DEFAULT_PHYSICS_HZ)
    mass = scene.model.body_mass[scene.base_body]
    changes = [{"t": 0.2, "parameter": "base_payload", "value": 1.0}]
    sim = Simulation(scene, make_controller("stand", robot), scenario(0.5, changes=changes))
    result = sim.run()
    assert result.status == "ok"
    # the extra kilogram loads the legs: the base sinks a little after t = 0.2 s
    assert scene.model.body_mass[scene.base_body] == mass
