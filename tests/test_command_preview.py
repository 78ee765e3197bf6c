"""The vectorised command preview equals the command timeline to the bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ridempc.autonomy.command_source import SourcedScenario
from ridempc.errors import ConfigError
from ridempc.scenarios import library_files, load_scenario_file
from ridempc.scenarios.scenario import Command, Scenario

FIELDS = tuple(Command.model_fields)


def _times(scenario: Scenario) -> np.ndarray:
    """A grid finer than the control tick over the ride, off the events' own times, plus
    each event's start and ramp end exactly and the MPC's horizon read past the end."""
    grid = np.arange(-0.01, scenario.duration + 0.5, 0.0037)
    edges = [c.t for c in scenario.commands] + [c.t + c.ramp for c in scenario.commands]
    edges += [w.start for w in scenario.waves] + [w.stop for w in scenario.waves]
    return np.concatenate([grid, np.asarray(edges, dtype=float)])


def _assert_agrees(scenario: Scenario, times: np.ndarray) -> None:
    commands = [scenario.command_at(float(t)) for t in times]
    for field in FIELDS:
        expected = np.array([getattr(c, field) for c in commands], dtype=np.float64)
        got = scenario.command_field_at(field, times)
        assert got.dtype == np.float64
        np.testing.assert_array_equal(got, expected, strict=True)
        assert np.array_equal(np.signbit(got), np.signbit(expected))


@pytest.mark.parametrize("path", library_files(), ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_every_library_timeline_agrees_exactly(path: Path) -> None:
    scenario = load_scenario_file(path)
    _assert_agrees(scenario, _times(scenario))


def test_ramps_waves_and_overlaps_agree_exactly() -> None:
    scenario = Scenario.model_validate(
        {
            "name": "mixed",
            "duration": 10.0,
            "commands": [
                {"t": 0.0, "velocity": 0.3},
                {"t": 1.0, "ramp": 1.5, "velocity": 1.1, "yaw_rate": -0.4},
                {"t": 1.7, "ramp": 0.6, "yaw_rate": 0.25, "roll": -0.05},
                {"t": 1.7, "lateral_offset": 0.02},
                {"t": 6.0, "ramp": 0.3, "velocity": 0.0, "roll": 0.0},
            ],
            "waves": [
                {"field": "roll", "amplitude": 0.1, "period": 1.3, "start": 2.0, "stop": 7.0},
                {"field": "roll", "amplitude": -0.03, "period": 0.7, "start": 3.0},
                {"field": "velocity", "amplitude": 0.2, "period": 2.0, "start": 4.0},
            ],
        }
    )
    rng = np.random.default_rng(0)
    _assert_agrees(scenario, np.concatenate([_times(scenario), rng.uniform(-1, 11, 2000)]))
    _assert_agrees(scenario, np.array([]))


def test_an_unknown_field_is_refused_with_the_allowed_ones() -> None:
    scenario = Scenario.model_validate({"name": "still", "duration": 1.0})
    with pytest.raises(ConfigError, match="'speed' is not one of velocity, yaw_rate"):
        scenario.command_field_at("speed", np.zeros(3))


def test_a_sourced_timeline_is_asked_at_each_time() -> None:
    scenario = SourcedScenario.model_validate(
        {"name": "sourced", "duration": 5.0, "commands": [{"t": 0.0, "velocity": 0.4}]}
    ).with_source(lambda t: Command(velocity=0.1 * t, yaw_rate=-0.2))
    times = np.linspace(0.0, 4.0, 17)
    np.testing.assert_array_equal(scenario.command_field_at("velocity", times), 0.1 * times)
    np.testing.assert_array_equal(scenario.command_field_at("yaw_rate", times), -0.2)
