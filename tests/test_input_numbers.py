"""Every number of every file a user can give or edit: NaN, infinities, strings, booleans
and absurd values are refused with one line naming the file, the field and the bad value.

The cases are generated: each file's raw table (a full scenario, every board.toml, every
robot.toml, every baseline gain file, every committed library manifest) is walked, and
every numeric leaf in it is replaced in turn by each bad value.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from pydantic import BaseModel

from ridempc.baselines.cassie_segway_gains import CassieSegwayGains, _overlay
from ridempc.baselines.cassie_standing_gains import CassieStandingGains
from ridempc.baselines.hovershoe_gains import CassieHovershoesGains
from ridempc.baselines.quadruped_skateboard_gains import QuadrupedSkateboardGains
from ridempc.boards.kinds import board_kind
from ridempc.cli import main
from ridempc.errors import ConfigError
from ridempc.library.format import Manifest
from ridempc.pair_description import PairDescription
from ridempc.paths import boards_dir, motion_library_dir, pairs_dir, robots_dir
from ridempc.robots.parameters import RobotParameters
from ridempc.scenarios import Scenario
from ridempc.tomlfile import read_toml, validate

BASELINES = Path(__file__).resolve().parents[1] / "ridempc" / "baselines"

# A scenario with every section and every numeric field (``changes`` is left out: its
# knobs are checked by their own tests).
FULL_SCENARIO: dict[str, Any] = {
    "name": "full",
    "duration": 5.0,
    "metrics_start": 0.5,
    "foot_offset": [0.01, -0.01],
    "platform_offsets": [[0.0, 0.01], [0.0, -0.01]],
    "commands": [
        {"t": 0.0, "velocity": 0.0, "yaw_rate": 0.0, "lateral_offset": 0.0, "roll": 0.0},
        {"t": 1.0, "ramp": 0.5, "velocity": 0.3, "yaw_rate": 0.1, "lateral_offset": 0.01,
         "roll": 0.05},
    ],  # fmt: skip
    "waves": [{"field": "roll", "amplitude": 0.1, "period": 3.0, "start": 1.0, "stop": 4.0}],
    "disturbances": [
        {"t": 2.0, "force": [10.0, 0.0, 0.0], "torque": [0.0, 0.0, 1.0], "duration": 0.1}
    ],
    "noise": {"imu_orientation_std": 0.002, "imu_gyro_std": 0.005, "imu_accel_std": 0.05,
              "encoder_resolution": 0.0004, "encoder_velocity_std": 0.01, "torque_std": 0.05,
              "vio_hz": 30.0, "vio_latency": 0.03, "vio_position_std": 0.01,
              "vio_yaw_std": 0.005, "vio_velocity_std": 0.02, "vio_yaw_rate_std": 0.01},
    "push_off": {"target": 0.5, "judged_at": 4.0},
}  # fmt: skip

# Beyond any physical figure in any unit the files use; every field refuses one of them.
ABSURD = (1e12, -1e12)
# (TOML spelling, Python value) of each value no number field may take.
NOT_NUMBERS: tuple[tuple[str, Any], ...] = (
    ("nan", math.nan),
    ("inf", math.inf),
    ("-inf", -math.inf),
    ('"1.0"', "1.0"),
    ("true", True),
)


def _numbers(raw: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """The path of every int or float leaf (never a bool) in a parsed TOML or JSON tree."""
    if isinstance(raw, dict):
        for key, value in raw.items():
            if key != "metadata":  # a library entry's free-form problem options
                yield from _numbers(value, (*path, key))
    elif isinstance(raw, list):
        for i, value in enumerate(raw):
            yield from _numbers(value, (*path, i))
    elif isinstance(raw, int | float) and not isinstance(raw, bool):
        yield path


def _replaced(raw: Any, path: tuple[Any, ...], value: Any) -> Any:
    copy = json.loads(json.dumps(raw))
    node = copy
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return copy


def _dotted(path: tuple[Any, ...]) -> str:
    return ".".join(str(p) for p in path)


def _files() -> list[tuple[str, type[BaseModel], dict[str, Any]]]:
    """(name, model, raw table) of every user-editable file with numbers."""
    files: list[tuple[str, type[BaseModel], dict[str, Any]]] = [
        ("scenario", Scenario, FULL_SCENARIO)
    ]
    for path in sorted(boards_dir().glob("*/board.toml")):
        raw = read_toml(path, "board file")
        files.append((f"board {path.parent.name}", board_kind(raw["kind"]).parameters, raw))
    for path in sorted(robots_dir().glob("*/robot.toml")):
        files.append((f"robot {path.parent.name}", RobotParameters, read_toml(path, "robot")))
    for path in sorted(pairs_dir().glob("*.toml")):
        files.append((f"pair {path.stem}", PairDescription, read_toml(path, "pair file")))
    for name, model in (
        ("cassie_standing", CassieStandingGains),
        ("cassie_hovershoes", CassieHovershoesGains),
        ("quadruped_skateboard", QuadrupedSkateboardGains),
    ):
        files.append((f"gains {name}", model, read_toml(BASELINES / f"{name}.toml", name)))
    segway = read_toml(BASELINES / "cassie_segway.toml", "segway gains")
    standing = read_toml(BASELINES / "cassie_standing.toml", "standing gains")
    segway["standing"] = _overlay(standing, segway.get("standing", {}))
    files.append(("gains cassie_segway", CassieSegwayGains, segway))
    for path in sorted(motion_library_dir().glob("*/manifest.json")):
        raw = json.loads(path.read_text())
        raw["entries"] = raw["entries"][:1]  # one entry stands for all: same model
        files.append((f"manifest {path.parent.name}", Manifest, raw))
    return files


def _cases() -> Iterator[Any]:
    for name, model, raw in _files():
        for path in _numbers(raw):
            yield pytest.param(model, raw, path, id=f"{name}:{_dotted(path)}")


CASES = list(_cases())


def test_the_walk_finds_the_numbers() -> None:
    ids = {c.id for c in CASES}
    for expected in ("scenario:commands.1.ramp", "scenario:noise.vio_hz",
                     "scenario:disturbances.0.force.0", "board hovershoes:platform_friction",
                     "robot cassie:fall_height", "gains cassie_standing:com_x.kp"):  # fmt: skip
        assert expected in ids
    assert len(CASES) > 300


def test_every_file_is_valid_as_given() -> None:
    for name, model, raw in _files():
        validate(Path(name), raw, model)


@pytest.mark.parametrize(("model", "raw", "path"), CASES)
def test_non_numbers_and_absurd_values_are_refused(model, raw, path) -> None:
    where = _dotted(path)
    for spelling, bad in NOT_NUMBERS:
        with pytest.raises(ConfigError) as refused:
            validate(Path("file.toml"), _replaced(raw, path, bad), model)
        message = str(refused.value)
        assert message.startswith("file.toml: field ") and "\n" not in message
        assert f"'{where}'" in message, message
        shown = {"nan": "nan", "inf": "inf", "-inf": "-inf", '"1.0"': "'1.0'", "true": "true"}
        assert f"got {shown[spelling]}" in message, message
    refused_absurd = 0
    for bad in ABSURD:
        try:
            validate(Path("file.toml"), _replaced(raw, path, bad), model)
        except ConfigError as exc:  # by the field's bound, or by a check across fields
            assert str(exc).startswith("file.toml: ") and "\n" not in str(exc)
            refused_absurd += 1
    assert refused_absurd >= 1, f"{where} has no bound: takes both {ABSURD}"


def _toml(raw: dict[str, Any]) -> str:
    """A minimal TOML writer for scenario tables, spelling NaN and infinities TOML's way."""

    def value(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float) and not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return json.dumps(v)

    lines, tables = [], []
    for key, v in raw.items():
        if isinstance(v, dict):
            tables.append(f"[{key}]\n" + "".join(f"{k} = {value(x)}\n" for k, x in v.items()))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                body = "".join(f"{k} = {value(x)}\n" for k, x in item.items())
                tables.append(f"[[{key}]]\n{body}")
        else:
            lines.append(f"{key} = {value(v)}")
    return "\n".join(lines) + "\n\n" + "\n".join(tables)


SCENARIO_PATHS = list(_numbers(FULL_SCENARIO))


@pytest.mark.parametrize("path", SCENARIO_PATHS, ids=_dotted)
def test_a_bad_scenario_number_ends_the_sim_command_with_one_line(
    capsys, tmp_path: Path, path
) -> None:
    for spelling, bad in NOT_NUMBERS:
        scenario = tmp_path / "bad.toml"
        scenario.write_text(_toml(_replaced(FULL_SCENARIO, path, bad)))
        out = tmp_path / "out"
        code = main(["sim", "--robot", "cyberdog2", "--scenario", str(scenario),
                     "--out", str(out)])  # fmt: skip
        err = capsys.readouterr().err
        assert code == 2, (spelling, err)
        assert len(err.strip().splitlines()) == 1
        assert err.startswith(f"ridempc: error: {scenario}: field '{_dotted(path)}'"), err
        assert not out.exists()


def test_the_full_scenario_rides_through_the_loader(tmp_path: Path) -> None:
    from ridempc.scenarios import load_scenario_file

    path = tmp_path / "full.toml"
    path.write_text(_toml(FULL_SCENARIO))
    assert load_scenario_file(path).noise.vio_hz == 30.0


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"metrics_start": 5.0}, "metrics_start = 5.0 s is after the end"),
        ({"commands": [{"t": 6.0, "velocity": 0.1}]}, "commands.0.t = 6.0 s"),
        ({"disturbances": [{"t": 9.0, "force": [1, 0, 0]}]}, "disturbances.0.t = 9.0 s"),
        ({"waves": [{"field": "roll", "amplitude": 0.1, "period": 1.0, "start": 7.0}]},
         "waves.0.start"),
        ({"waves": [{"field": "roll", "amplitude": 0.1, "period": 1.0, "start": 2.0,
                     "stop": 1.0}]}, "stop (1.0 s) must come after start"),
        ({"push_off": {"target": 0.5, "judged_at": 5.5}}, "push_off.judged_at = 5.5 s"),
        ({"changes": [{"t": 8.0, "parameter": "floor_friction", "value": 0.5}]},
         "changes.0.t = 8.0 s"),
    ],
)  # fmt: skip
def test_an_event_after_the_end_of_the_ride_is_refused(change, words) -> None:
    with pytest.raises(ConfigError, match=re.escape(words)):
        validate(Path("file.toml"), {**FULL_SCENARIO, **change}, Scenario)


def test_platform_offsets_need_independent_platforms(capsys, tmp_path: Path) -> None:
    scenario = tmp_path / "offsets.toml"
    scenario.write_text('name = "o"\nduration = 1.0\nplatform_offsets = [[0.0, 0.1]]\n')
    for board in ("none", "segway", "hovershoes"):  # none, one platform, two platforms
        code = main(["sim", "--robot", "cassie", "--board", board, "--controller", "stand",
                     "--scenario", str(scenario), "--out", str(tmp_path / "o")])  # fmt: skip
        err = capsys.readouterr().err
        assert code == 2 and "platform_offsets" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def _tables(raw: Any, path: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """The path of every table (dict) in a parsed tree, the top level included."""
    if isinstance(raw, dict):
        yield path
        for key, value in raw.items():
            if key != "metadata":
                yield from _tables(value, (*path, key))
    elif isinstance(raw, list):
        for i, value in enumerate(raw):
            yield from _tables(value, (*path, i))


def _table_cases() -> Iterator[Any]:
    for name, model, raw in _files():
        for path in _tables(raw):
            yield pytest.param(model, raw, path, id=f"{name}:{_dotted(path) or 'top'}")


@pytest.mark.parametrize(("model", "raw", "path"), list(_table_cases()))
def test_an_unknown_key_names_the_keys_its_table_takes(model, raw, path) -> None:
    table = json.loads(json.dumps(raw))
    node = table
    for part in path:
        node = node[part]
    existing = list(node)
    node["zz_typo"] = 1.0
    try:
        validate(Path("file.toml"), table, model)
    except ConfigError as refused:
        message = str(refused)
    else:  # a mapping of names to numbers takes any name
        assert path[-1] in ("board_final", "tolerances"), path
        return
    assert f"'{_dotted((*path, 'zz_typo'))}'" in message, message
    if "unknown key" in message:  # a table of fields, not a mapping of names (motors)
        allowed = message.split("allowed: ")[1].split(", ")
        assert set(existing) <= set(allowed), message
