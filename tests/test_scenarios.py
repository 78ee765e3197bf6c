"""Scenario files are validated on load; the timeline gives the command in force."""

from __future__ import annotations

from pathlib import Path

import pytest

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.scenarios import (
    library_files,
    load_scenario_file,
    resolve_scenario,
    scenario_applies,
)
from ridempc.scenarios.scenario import Command


@pytest.mark.parametrize("path", library_files(), ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_every_library_file_loads_under_its_name(path: Path) -> None:
    scenario = load_scenario_file(path)
    assert scenario.name == path.stem
    assert scenario.duration > 0
    if path.parent.name != "library":  # a board's variant applies to that board only
        assert scenario.boards == (path.parent.name,)


def test_board_variants_resolve_by_board() -> None:
    assert resolve_scenario("push", "skateboard").disturbances[1].body == "board/deck"
    assert resolve_scenario("push", "none").disturbances[0].body == "base"
    assert resolve_scenario("velocity-steps", "hovershoes").command_at(30.0).velocity == 1.5
    assert resolve_scenario("velocity-steps", "segway").command_at(25.0).velocity == 4.0
    with pytest.raises(ConfigError, match="does not apply to board 'skateboard'"):
        resolve_scenario("wave", "skateboard")
    assert scenario_applies("roll-tracking", "cyberdog2", "skateboard")
    assert scenario_applies("push-off-0.5", "go1", "skateboard")  # any quadruped
    assert not scenario_applies("push-off-0.5", "none", "skateboard")  # a dead weight
    assert not scenario_applies("roll-tracking", "cassie", "skateboard")
    assert not scenario_applies("wave", "cassie", "segway")


def test_waves_add_a_sinusoid() -> None:
    scenario = resolve_scenario("roll-tracking", "skateboard")
    assert scenario.command_at(1.0).roll == 0.0
    assert scenario.command_at(2.75).roll == pytest.approx(0.1)  # a quarter period in
    assert scenario.command_at(4.25).roll == pytest.approx(-0.1)


def test_unknown_scenario_names_the_valid_ones() -> None:
    with pytest.raises(UnknownNameError, match="stand-still"):
        resolve_scenario("no-such-scenario")


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ('name = "x"\n', "duration"),
        ('name = "x"\nduration = -1.0\n', "duration"),
        ('name = "x"\nduration = 1.0\nspeed = 3\n', "speed"),
        (
            'name = "x"\nduration = 1.0\n[[commands]]\nt = 0.0\nvelocity = "fast"\n',
            "commands.0.velocity",
        ),
        (
            'name = "x"\nduration = 1.0\n[[disturbances]]\nt = 1.0\nforce = [1, 2]\n',
            "disturbances.0.force",
        ),
        ('name = "x"\nduration = 1.0\n[noise]\nvio_latency = -0.1\n', "noise.vio_latency"),
        (
            'name = "x"\nduration = 1.0\n[[changes]]\nt = 1.0\nparameter = "gravity"\nvalue = 1\n',
            "changes.0.parameter",
        ),
    ],
)
def test_malformed_scenarios_name_the_field(tmp_path: Path, text: str, field: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=f"field '{field}"):
        load_scenario_file(path)


def test_not_toml_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "bad.toml"
    path.write_text("name = = 3")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_scenario_file(path)


def test_command_timeline_steps_and_ramps(tmp_path: Path) -> None:
    path = tmp_path / "steps.toml"
    path.write_text(
        'name = "steps"\nduration = 10.0\n'
        "[[commands]]\nt = 0.0\nvelocity = 0.0\n"
        "[[commands]]\nt = 2.0\nvelocity = 1.0\nramp = 1.0\n"
        "[[commands]]\nt = 5.0\nyaw_rate = 0.5\n"
    )
    scenario = load_scenario_file(path)
    assert scenario.command_at(1.0).velocity == 0.0
    assert scenario.command_at(2.5).velocity == pytest.approx(0.5)
    assert scenario.command_at(4.0).velocity == 1.0
    assert scenario.command_at(6.0).velocity == 1.0  # kept when a later event sets other fields
    assert scenario.command_at(6.0).yaw_rate == 0.5
    for t in (0.0, 2.5, 6.0):  # built unchecked, it is the command a check would build
        command = scenario.command_at(t)
        assert command == Command(**command.model_dump())
        assert command.model_fields_set == set(Command.model_fields)


@pytest.mark.parametrize("robot", ["cyberdog2", "go1"])
def test_each_skateboard_library_target_has_a_push_off_scenario(robot: str) -> None:
    """``push-off-<target>`` for each committed push-off from rest (``accelerate``; a
    ``repush`` starts rolling) of each quadruped's library, judged at the end of the entry's
    push-off."""
    from ridempc.library.store import library_folder, load_library

    _, entries = load_library(library_folder(robot, "skateboard"))
    for entry in (e for e in entries if e.record.kind == "accelerate"):
        scenario = resolve_scenario(f"push-off-{entry.record.target:.1f}", "skateboard")
        assert scenario.push_off is not None
        assert scenario.push_off.target == pytest.approx(entry.record.target)
        start = next(e.t for e in scenario.commands if e.velocity == entry.record.target)
        push_off_end = start + entry.record.n_intervals * entry.record.dt
        assert scenario.push_off.judged_at == pytest.approx(push_off_end)
        assert scenario.command_at(scenario.push_off.judged_at).velocity == entry.record.target
        assert scenario.metrics_start > scenario.push_off.judged_at  # roll tracking after it
