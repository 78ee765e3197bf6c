"""Terrain: ``[[terrain]]`` parsing and checks, the scene's boxes, falls judged against it."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.cli import main
from ridempc.errors import ConfigError
from ridempc.robots import load_robot
from ridempc.run import RideRequest, check_request
from ridempc.scenarios import load_scenario_file
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.falls import FallDetector
from ridempc.sim.levelling import step_levelling
from ridempc.sim.scene import build_scene
from ridempc.sim.terrain import STEP_DOWN_RADII, lay_out

HEAD = 'name = "t"\nduration = 2.0\n'
STEP = '[[terrain]]\nkind = "step"\nat = 2.0\nheight = 0.05\ndirection = "down"\n'
SLOPE = '[[terrain]]\nkind = "slope"\nstart = 3.0\nlength = 2.0\nangle = 10.0\ndirection = "up"\n'


def _load(tmp_path: Path, body: str):
    path = tmp_path / "s.toml"
    path.write_text(HEAD + body)
    return load_scenario_file(path)


def test_every_kind_parses(tmp_path: Path) -> None:
    body = (
        STEP
        + SLOPE
        + (
            '[[terrain]]\nkind = "stairs"\nat = 6.0\nheights_radii = [0.79, 0.93]\ntread = 0.5\n'
            'direction = "down"\n'
            '[[terrain]]\nkind = "rough"\nstart = 8.0\nlength = 2.0\namplitude = 0.01\n'
            "wavelength = 0.3\n"
            '[[terrain]]\nkind = "strip"\nstart = 11.0\nlength = 2.0\ny = [0.05, 0.5]\n'
            "height = 0.03\nramp = 0.3\n"
            '[[terrain]]\nkind = "box"\ncenter = [14.0, 1.0]\nsize = [0.2, 0.2, 0.1]\n'
        )
    )
    kinds = [item.kind for item in _load(tmp_path, body).terrain]
    assert kinds == ["step", "slope", "stairs", "rough", "strip", "box"]


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (STEP.replace("0.05", "nan"), "terrain.0.step.height"),
        (STEP.replace("0.05", "inf"), "terrain.0.step.height"),
        (STEP.replace("height = 0.05", "height = 0.05\nheight_radii = 1.0"), "exactly one"),
        (STEP.replace("2.0", "150.0"), "terrain.0.step.at"),
        (STEP.replace("2.0", "0.1"), "terrain.0.step.at"),
        (SLOPE.replace("10.0", "45.0"), "terrain.0.slope.angle"),
        (SLOPE.replace("length = 2.0", "length = 99.0"), "outside the world"),
        (STEP.replace("2.0", "4.0") + SLOPE, "terrain.1: slope overlaps terrain.0"),
        (STEP + STEP, "terrain.1: step overlaps terrain.0"),
        (STEP.replace('"step"', '"cliff"'), "terrain.0"),
        (STEP + "colour = 1\n", "unknown key"),
    ],
)
def test_bad_terrain_is_refused_naming_the_field(tmp_path: Path, body: str, words: str) -> None:
    with pytest.raises(ConfigError, match=words.replace(".", r"\.")) as info:
        _load(tmp_path, body)
    assert "\n" not in str(info.value)


def test_a_step_higher_than_the_board_rolls_down_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "s.toml"
    path.write_text(HEAD + STEP.replace("height = 0.05", "height_radii = 2.5"))
    request = RideRequest("cassie", "hovershoes", "pd", path, out=None)
    with pytest.raises(ConfigError, match=r"field 'terrain\.0\.height_radii'.*can roll down"):
        check_request(request)


def test_the_profile_boxes_have_the_steps_and_slopes_heights(tmp_path: Path) -> None:
    scenario = _load(tmp_path, STEP + SLOPE)
    layout = lay_out(scenario.terrain, wheel_radius=0.05)
    rise = 2.0 * math.tan(math.radians(10.0))
    assert layout.floor_z == pytest.approx(-0.05)
    assert layout.edges == ((2.0, -0.05),)
    for x, z in [
        (0.0, 0.0),
        (1.99, 0.0),
        (2.01, -0.05),
        (4.0, -0.05 + rise / 2),
        (6.0, rise - 0.05),
    ]:
        assert layout.height_at(x, 0.3) == pytest.approx(z, abs=1e-9)
    # the compiled boxes: ray casts straight down hit the terrain at those heights
    board = load_board("hovershoes")
    scene = build_scene(load_robot("cassie"), DEFAULT_PHYSICS_HZ, board=board, terrain=layout)
    model, data = scene.model, scene.data
    hit = np.zeros(1, dtype=np.int32)
    for x in (1.0, 2.5, 3.5, 4.5, 6.0, 20.0):
        start = np.array([x, 3.0, 2.0])
        distance = mujoco.mj_ray(model, data, start, np.array([0.0, 0.0, -1.0]), None, 1, -1, hit)
        assert int(hit[0]) in scene.ground_geoms
        assert 2.0 - distance == pytest.approx(layout.height_at(x, 3.0), abs=1e-6)
    # the rider starts on the level it started on before (z = 0)
    assert scene.support_height == pytest.approx(board.platform_top, abs=2e-3)


def test_rough_patch_and_strip_heights(tmp_path: Path) -> None:
    body = (
        '[[terrain]]\nkind = "rough"\nstart = 1.0\nlength = 2.0\namplitude = 0.01\n'
        "wavelength = 0.3\n"
        '[[terrain]]\nkind = "strip"\nstart = 4.0\nlength = 2.0\ny = [0.05, 0.5]\n'
        "height_radii = 0.5\nramp = 0.5\n"
    )
    layout = lay_out(_load(tmp_path, body).terrain, wheel_radius=0.04)
    heights = [
        layout.height_at(x, y) for x in np.linspace(1, 3, 41) for y in np.linspace(-1, 1, 41)
    ]
    assert max(np.abs(heights)) == pytest.approx(0.01, rel=0.05)  # bumps and cracks
    assert layout.height_at(1.0, 0.0) == pytest.approx(0.0, abs=1e-9)  # tapered to the level
    assert layout.floor_z < -0.005  # the floor under the cracks
    assert layout.height_at(5.0, 0.2) == pytest.approx(0.02)
    assert layout.height_at(4.25, 0.2) == pytest.approx(0.01)  # half way up the ramp
    assert layout.height_at(5.0, -0.2) == pytest.approx(0.0)  # the other shoe's side


def test_radii_need_a_board(tmp_path: Path) -> None:
    scenario = _load(tmp_path, STEP.replace("height = 0.05", "height_radii = 1.0"))
    with pytest.raises(ConfigError, match="no wheels"):
        lay_out(scenario.terrain, wheel_radius=None)
    layout = lay_out(scenario.terrain, wheel_radius=0.05)
    assert layout.edges == ((2.0, -0.05),)
    assert STEP_DOWN_RADII * 0.05 > 0.05


def test_falls_are_judged_against_the_terrain_under_the_rider(tmp_path: Path) -> None:
    scenario = _load(tmp_path, STEP.replace("0.05", "0.6").replace("down", "up"))
    layout = lay_out(scenario.terrain, wheel_radius=None)
    robot = load_robot("cassie")
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, terrain=layout)
    model, data = scene.model, scene.data
    falls = FallDetector(scene)
    assert falls.check(model, data) is None
    root = model.jnt_qposadr[model.body_jntadr[model.body_rootid[scene.base_body]]]
    # past the step up at the start's height: the base is below its fall height over the
    # ground there, though high over the start's level
    data.qpos[root] += 3.0
    mujoco.mj_forward(model, data)
    limit = robot.params.fall_height + 0.6
    assert f"below {limit:.3f} m" in (falls.check(model, data) or "")
    # standing on the upper level
    data.qpos[root + 2] += 0.6
    mujoco.mj_forward(model, data)
    assert falls.check(model, data) is None


def test_a_short_ride_down_a_curb(tmp_path: Path) -> None:
    """A dead weight on the Segway, pushed for 0.6 s, rolls down a curb of half its wheel
    radius: no fall, the board a curb lower, the step's crossing in the summary."""
    path = tmp_path / "curb.toml"
    path.write_text(
        'name = "curb"\nduration = 2.0\n'
        '[[disturbances]]\nt = 0.0\nbody = "base"\nforce = [150.0, 0.0, 0.0]\nduration = 0.6\n'
        '[[terrain]]\nkind = "step"\nat = 0.6\nheight_radii = 0.5\ndirection = "down"\n'
    )
    checked = check_request(RideRequest("none", "segway", "dead-weight", path, out=None))
    result = checked.simulation.run()
    assert result.status == "ok", result.fall_reason
    curb = 0.5 * load_board("segway").params.wheel_radius  # type: ignore[attr-defined]
    z = result.log["board_position"][:, 0, 2]
    assert z[0] - z[-1] == pytest.approx(curb, abs=0.005)
    steps = step_levelling(result.log, checked.scenario)["steps"]
    assert steps[0]["x_m"] == 0.6
    assert 0.0 < steps[0]["crossed_s"] < 2.0


def test_level_after_is_the_time_from_the_crossing_to_the_last_tilt(tmp_path: Path) -> None:
    scenario = _load(tmp_path, STEP)  # an edge at x = 2 m
    time = np.arange(0.0, 3.0, 0.01)
    position = np.zeros((len(time), 2, 3))
    position[:, :, 0] = time[:, None]  # both platforms at 1 m/s: crossing at 2 s
    position[:, 1, 0] -= 0.05  # the second one 5 cm behind: crossing at 2.05 s
    tilt = np.where((time > 2.1) & (time < 2.4), math.radians(5.0), 0.0)
    quaternion = np.zeros((len(time), 2, 4))
    quaternion[:, :, 0] = np.cos(tilt / 2)[:, None]
    quaternion[:, :, 2] = np.sin(tilt / 2)[:, None]  # pitched about y
    log = {"time": time, "board_position": position, "board_quaternion": quaternion}
    (step,) = step_levelling(log, scenario)["steps"]
    assert step["crossed_s"] == pytest.approx(2.05, abs=0.011)
    assert step["level_after_s"] == pytest.approx(0.35, abs=0.011)
    quaternion[-1, 0] = [np.cos(0.1), 0.0, np.sin(0.1), 0.0]  # tilted at the end: never level
    assert step_levelling(log, scenario)["steps"][0]["level_after_s"] is None


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (STEP.replace("height = 0.05", "height_radii = 2.5"), "terrain.0.height_radii"),
        (STEP.replace("2.0", "4.0") + SLOPE, "terrain.1: slope overlaps terrain.0"),
    ],
)
def test_the_cli_refuses_bad_terrain_in_one_line_before_anything_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str, words: str
) -> None:
    path = tmp_path / "s.toml"
    path.write_text(HEAD + body)
    out = tmp_path / "out"
    code = main(
        ["sim", "--robot", "cassie", "--board", "hovershoes", "--controller", "pd",
         "--scenario", str(path), "--out", str(out), "--no-plots"]
    )  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err.startswith(f"ridempc: error: {path}:") and "\n" not in err
    assert words in err
    assert not out.exists() or not any(out.iterdir())
