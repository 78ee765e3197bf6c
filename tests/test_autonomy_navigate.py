"""``ridempc navigate``: courses checked before riding, and the navigator's stop and hold."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from autonomy_fakes import BlindSensor, KinematicRider

from ridempc.autonomy.command_source import SourcedScenario
from ridempc.autonomy.course import course_names, resolve_course
from ridempc.autonomy.navigate import check_reachable
from ridempc.autonomy.navigator import Navigator, NavigatorSettings
from ridempc.autonomy.occupancy import GridFrame, OccupancyGrid
from ridempc.autonomy.teb import Band
from ridempc.cli import main
from ridempc.scenarios.scenario import Command

HZ = 300  # [Hz] the navigator's steps: 10 Hz planning is every 30th

ENCLOSED = """name = "enclosed"
duration = 10.0
goal = [4.0, 0.0]
{boxes}
"""


def _box(x: float, y: float, sx: float, sy: float, sz: float = 0.5) -> str:
    return f"\n[[obstacles]]\ncenter = [{x}, {y}]\nsize = [{sx}, {sy}, {sz}]\n"


@pytest.mark.parametrize("name", course_names())
def test_library_courses_load_and_are_reachable(name: str) -> None:
    course = resolve_course(name)
    path = check_reachable(course.in_start_frame(), name, NavigatorSettings())
    assert np.linalg.norm(path[-1] - np.asarray(course.goal)) < 0.1


def test_an_unreachable_goal_is_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    boxes = _box(4.0, 1.0, 2.2, 0.2) + _box(4.0, -1.0, 2.2, 0.2)
    boxes += _box(3.0, 0.0, 0.2, 2.2) + _box(5.0, 0.0, 0.2, 2.2)
    course = tmp_path / "enclosed.toml"
    course.write_text(ENCLOSED.format(boxes=boxes))
    out = tmp_path / "out"
    assert main(["navigate", "--course", str(course), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "field 'goal'" in err[0] and "unreachable" in err[0]
    assert not (out / "summary.json").exists()


@pytest.mark.parametrize(("height", "reachable"), [(0.1, True), (0.5, False)])
def test_a_course_whose_only_way_is_a_straddle_is_reachable(
    tmp_path: Path, capsys: pytest.CaptureFixture, height: float, reachable: bool
) -> None:
    # the goal's room is entered by a passage 0.9 m wide, the rider's centre 0.1 m a side
    # of its middle: no way round the box in it
    boxes = _box(4.0, 1.0, 2.2, 0.2) + _box(4.0, -1.0, 2.2, 0.2) + _box(5.0, 0.0, 0.2, 2.2)
    boxes += _box(3.0, 0.775, 0.2, 0.65) + _box(3.0, -0.775, 0.2, 0.65)
    boxes += _box(2.5, 0.55, 1.0, 0.2) + _box(2.5, -0.55, 1.0, 0.2)
    boxes += _box(2.6, 0.0, 0.6, 0.2, height)
    course = tmp_path / "narrow.toml"
    course.write_text(ENCLOSED.format(boxes=boxes))
    if reachable:
        loaded = resolve_course(str(course))
        path = check_reachable(loaded, "narrow", NavigatorSettings())
        assert np.linalg.norm(path[-1] - np.asarray(loaded.goal)) < 0.1
        return
    assert main(["navigate", "--course", str(course), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unreachable" in err[0] and "straddling" in err[0]


def test_a_goal_inside_a_box_is_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    course = tmp_path / "inside.toml"
    course.write_text(ENCLOSED.format(boxes=_box(4.0, 0.0, 0.4, 0.4)))
    assert main(["navigate", "--course", str(course), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "inside obstacles.0" in err[0]


SLOPE = """
[[terrain]]
kind = "slope"
start = {start}
length = 2.0
angle = 7.0
direction = "up"
"""


def test_a_course_carries_terrain(tmp_path: Path) -> None:
    course = tmp_path / "slope.toml"
    course.write_text(ENCLOSED.format(boxes="") + SLOPE.format(start=1.5))
    loaded = resolve_course(str(course))
    assert loaded.terrain[0].kind == "slope"
    assert loaded.in_start_frame().terrain == loaded.terrain


def test_terrain_under_the_start_is_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    course = tmp_path / "slope.toml"
    course.write_text(ENCLOSED.format(boxes="") + SLOPE.format(start=0.2))
    assert main(["navigate", "--course", str(course), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "terrain.0.slope.start" in err[0] and "0.2" in err[0]
    assert not (tmp_path / "o").exists()


def test_sourced_scenario_asks_its_source() -> None:
    scenario = SourcedScenario(name="x", duration=5.0).with_source(
        lambda t: Command(velocity=0.1 * t)
    )
    assert scenario.with_duration(3.0).command_at(2.0).velocity == pytest.approx(0.2)


class _Controller:
    def __init__(self) -> None:
        self.position = np.array([0.0, 0.0, 1.0])

    def estimate(self) -> SimpleNamespace:
        return SimpleNamespace(
            base_position=self.position, base_quaternion=np.array([1.0, 0, 0, 0])
        )


def _navigator() -> Navigator:
    grid = OccupancyGrid(GridFrame((-2.0, -2.0), 0.05, (160, 80)))
    return Navigator(np.array([5.0, 0.0]), grid, BlindSensor(), _Controller(), HZ)  # type: ignore[arg-type]


def _ride(navigator: Navigator, until: float) -> list[Command]:
    commands = []
    for tick in range(round(until * HZ)):
        t = tick / HZ
        navigator(t, None, None)
        commands.append(navigator.command_at(t))
    return commands


def test_the_navigator_sets_off_after_its_delay_and_within_its_limits() -> None:
    navigator = _navigator()
    commands = _ride(navigator, 4.0)
    speeds = np.array([c.velocity for c in commands])
    assert speeds[: round(HZ * navigator.settings.start_delay)].max() == 0.0
    assert speeds[-1] > 0.3
    assert np.diff(speeds).max() * HZ <= navigator.settings.accel + 1e-9
    assert navigator.stop_reason is None and navigator.band_failures == 0


def test_a_failing_planner_stops_the_rider_and_holds(monkeypatch: pytest.MonkeyPatch) -> None:
    navigator = _navigator()
    _ride(navigator, 4.0)
    failed = Band(np.zeros((10, 3)), np.ones(9), success=False, solve_time=0.0)
    monkeypatch.setattr(navigator.teb, "solve", lambda *args, **kwargs: failed)
    commands = _ride_on(navigator, 4.0, 8.0)
    s = navigator.settings
    assert navigator.band_failures == s.failures_to_stop
    assert navigator.stop_reason is not None and "failed 3 times" in navigator.stop_reason
    assert commands[-1].velocity == 0.0 and commands[-1].yaw_rate == 0.0  # held
    decel = -np.diff([c.velocity for c in commands]).max() * HZ
    assert decel <= s.stop_decel + 1e-9
    assert navigator.summary()["stopped_at_s"] == pytest.approx(
        4.0 + 0.1 * (s.failures_to_stop - 1), abs=0.11
    )


def _ride_on(navigator: Navigator, start: float, until: float) -> list[Command]:
    commands = []
    for tick in range(round(start * HZ), round(until * HZ)):
        t = tick / HZ
        navigator(t, None, None)
        commands.append(navigator.command_at(t))
    assert math.isfinite(commands[-1].velocity)
    return commands


def test_a_kinematic_rider_reaches_the_corridors_goal_clear_of_its_boxes() -> None:
    from ridempc.autonomy.evaluation import rasterise
    from ridempc.autonomy.navigate import map_frame

    course = resolve_course("corridor").in_start_frame()
    frame = map_frame(course)
    grid = OccupancyGrid(frame)
    grid.log_odds[rasterise(frame, course.obstacles)] = 3.0  # the map the camera would build
    rider = KinematicRider()
    hz = 300
    navigator = Navigator(np.asarray(course.goal), grid, BlindSensor(), rider, hz)  # type: ignore[arg-type]
    clearance = math.inf
    for tick in range(round(course.duration * hz)):
        t = tick / hz
        navigator(t, None, None)
        rider.step(navigator.command_at(t), 1.0 / hz)
        for box in course.obstacles:
            for margin in (0.3, 0.35):
                if box.contains(rider.pose[:2], margin)[0]:
                    clearance = min(clearance, margin)
    assert navigator.arrived_at is not None
    assert np.hypot(*(rider.pose[:2] - course.goal)) < course.goal_tolerance
    assert clearance > 0.35  # the base never within 0.35 m of a box
