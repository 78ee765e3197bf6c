"""A scenario's ``[[changes]]``: each knob, by value and by scale, changes the scene as it
says; out-of-range values and names that do not fit the pair are refused in one line before
the ride; a slippery floor changes a ride; a payload moves the rider's mass, centre of mass
and inertia as MuJoCo computes them; a change at t > 0 waits for its step."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

import ridempc.sim.scene as scene_module
from ridempc.boards.registry import load_board
from ridempc.cli import main
from ridempc.controllers import make_controller
from ridempc.errors import ConfigError
from ridempc.robots import load_robot
from ridempc.scenarios import load_scenario_file
from ridempc.scenarios.scenario import CommandEvent, ParameterChange, Scenario
from ridempc.sim.changes import ScheduledChanges
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.knobs import KNOBS, SCALE_MAX
from ridempc.sim.scene import BOARD_PREFIX, Scene, build_scene
from ridempc.sim.simulation import Simulation

RIDER = {"hovershoes": "cassie", "segway": "cassie", "skateboard": "cyberdog2", "none": "cassie"}


@cache
def _scene(board: str) -> Scene:
    return build_scene(load_robot(RIDER[board]), DEFAULT_PHYSICS_HZ, load_board(board))


def _simulation(board: str, *changes: dict[str, Any], duration: float = 0.01) -> Simulation:
    scene = _scene(board)
    assert scene.robot is not None
    scenario = Scenario(
        name="changes", duration=duration, changes=tuple(ParameterChange(**c) for c in changes)
    )
    return Simulation(scene, make_controller("stand", scene.robot, board), scenario)


def _id(scene: Scene, kind: mujoco.mjtObj, name: str) -> int:
    found = mujoco.mj_name2id(scene.model, kind, name)
    assert found >= 0, name
    return found


def _geom_friction(name: str) -> Callable[[Simulation], float]:
    return lambda sim: float(
        sim.scene.model.geom_friction[_id(sim.scene, mujoco.mjtObj.mjOBJ_GEOM, name), 0]
    )


def _body_mass(name: str) -> Callable[[Simulation], float]:
    return lambda sim: float(
        sim.scene.model.body_mass[_id(sim.scene, mujoco.mjtObj.mjOBJ_BODY, name)]
    )


def _geom_size(name: str) -> Callable[[Simulation], float]:
    return lambda sim: float(
        sim.scene.model.geom_size[_id(sim.scene, mujoco.mjtObj.mjOBJ_GEOM, name), 0]
    )


def _joint(array: str, name: str) -> Callable[[Simulation], float]:
    def read(sim: Simulation) -> float:
        joint = _id(sim.scene, mujoco.mjtObj.mjOBJ_JOINT, name)
        index = joint if array.startswith("jnt_") else sim.scene.model.jnt_dofadr[joint]
        return float(getattr(sim.scene.model, array)[index])

    return read


def _gain(*path: str) -> Callable[[Simulation], float]:
    def read(sim: Simulation) -> float:
        node: Any = sim.firmware.params  # type: ignore[union-attr]
        for key in path:
            node = getattr(node, key)
        return float(node)

    return read


def _peak_torque(sim: Simulation) -> float:
    """The first motor's torque available at standstill [N m] (its curve's peak)."""
    driver = sim.driver
    assert driver is not None
    return float(driver.curve.limit(np.zeros(len(sim.scene.actuator_ids)))[0])


# (board, the change without value or scale, what it reads, a value, a scale)
CASES: list[tuple[str, dict[str, Any], Callable[[Simulation], float], float, float]] = [
    ("hovershoes", {"parameter": "floor_friction"}, _geom_friction("floor"), 0.3, 0.5),
    ("skateboard", {"parameter": "floor_friction"}, _geom_friction("floor"), 0.05, 2.0),
    (
        "hovershoes",
        {"parameter": "tyre_friction"},
        _geom_friction(BOARD_PREFIX + "left_tyre"),
        0.4,
        0.7,
    ),
    (
        "segway",
        {"parameter": "tyre_friction"},
        _geom_friction(BOARD_PREFIX + "right_tyre"),
        0.8,
        1.2,
    ),
    (
        "hovershoes",
        {"parameter": "deck_friction"},
        _geom_friction(BOARD_PREFIX + "right_deck"),
        0.5,
        0.4,
    ),
    ("skateboard", {"parameter": "deck_friction"}, _geom_friction(BOARD_PREFIX + "deck"), 0.6, 0.8),
    (
        "hovershoes",
        {"parameter": "board_mass", "body": "left_shoe"},
        _body_mass(BOARD_PREFIX + "left_shoe"),
        3.0,
        1.5,
    ),
    (
        "segway",
        {"parameter": "board_mass", "body": "chassis"},
        _body_mass(BOARD_PREFIX + "chassis"),
        20.0,
        0.8,
    ),
    (
        "skateboard",
        {"parameter": "board_mass", "body": "wheel_fl"},
        _body_mass(BOARD_PREFIX + "wheel_fl"),
        0.2,
        2.0,
    ),
    (
        "hovershoes",
        {"parameter": "wheel_radius"},
        _geom_size(BOARD_PREFIX + "left_tyre"),
        0.04,
        0.95,
    ),
    ("segway", {"parameter": "wheel_radius"}, _geom_size(BOARD_PREFIX + "left_tyre"), 0.15, 0.9),
    (
        "skateboard",
        {"parameter": "wheel_radius"},
        _geom_size(BOARD_PREFIX + "wheel_rr"),
        0.035,
        1.1,
    ),
    (
        "skateboard",
        {"parameter": "bushing_stiffness"},
        _joint("jnt_stiffness", BOARD_PREFIX + "truck_front"),
        20.0,
        0.5,
    ),
    (
        "skateboard",
        {"parameter": "bushing_damping"},
        _joint("dof_damping", BOARD_PREFIX + "truck_rear"),
        1.0,
        3.0,
    ),
    (
        "hovershoes",
        {"parameter": "firmware_gain", "gain": "pitch_kp"},
        _gain("pitch_kp"),
        30.0,
        0.8,
    ),
    (
        "segway",
        {"parameter": "firmware_gain", "gain": "turn_gain"},
        _gain("gains", "turn_gain"),
        5.0,
        1.3,
    ),
    ("skateboard", {"parameter": "motor_torque_limit"}, _peak_torque, math.nan, 0.5),
    (
        "none",
        {"parameter": "joint_damping"},
        _joint("dof_damping", "left_knee"),
        2.0,
        3.0,
    ),
    (
        "skateboard",
        {"parameter": "joint_damping", "joint": "FR_knee"},
        _joint("dof_damping", "FR_knee"),
        0.5,
        2.0,
    ),
]


def _case_id(case: tuple) -> str:
    board, fields = case[0], case[1]
    where = fields.get("body") or fields.get("gain") or fields.get("joint") or ""
    return "-".join(filter(None, (fields["parameter"], where, board)))


def test_every_knob_has_a_case() -> None:
    covered = {fields["parameter"] for _, fields, *_ in CASES}
    assert covered | {"payload", "base_payload"} == set(KNOBS)


@pytest.mark.parametrize("form", ["value", "scale"])
@pytest.mark.parametrize("case", CASES, ids=[_case_id(c) for c in CASES])
def test_each_knob_sets_its_parameter(case: tuple, form: str) -> None:
    board, fields, read, value, scale = case
    if form == "value" and "value" not in KNOBS[fields["parameter"]].forms:
        pytest.skip(f"{fields['parameter']} takes a scale only")
    amount = value if form == "value" else scale
    sim = _simulation(board, {**fields, form: amount})
    nominal = read(sim)
    assert nominal > 0.0 or fields["parameter"] == "joint_damping"
    expected = amount if form == "value" else nominal * scale
    try:
        assert sim.changes.apply(0, sim.scene.data)
        assert read(sim) == pytest.approx(expected, rel=1e-12)
    finally:
        sim.changes.restore()
    assert read(sim) == nominal  # undone


def _joint_names(scene: Scene) -> list[str]:
    model = scene.model
    return [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "" for j in range(model.njnt)]


def test_case_joints_exist() -> None:
    assert "left_knee" in _joint_names(_scene("none"))
    assert "FR_knee" in _joint_names(_scene("skateboard"))


def test_a_slippery_floor_governs_its_contacts() -> None:
    """The floor's pairs follow the product rule: a 0.3 floor under the nominal (1.0) tyres
    and feet grips at 0.3, under the 1.5 decks at 0.45; the tyres' change multiplies it."""
    sim = _simulation(
        "hovershoes",
        {"parameter": "floor_friction", "value": 0.3},
        {"parameter": "tyre_friction", "scale": 0.5},
    )
    model = sim.scene.model
    floor = _id(sim.scene, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    try:
        sim.changes.apply(0, sim.scene.data)
        floor_pairs = np.flatnonzero(model.pair_geom1 == floor)  # the world's body comes first
        assert len(floor_pairs) == 15 + 4  # Cassie's collision geoms, the decks and tyres
        for pair in floor_pairs:
            other = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, model.pair_geom2[pair])
            expected = {"tyre": 0.15, "deck": 0.45}.get((other or "").split("_")[-1], 0.3)
            assert model.pair_friction[pair, 0] == pytest.approx(expected), other
    finally:
        sim.changes.restore()


def test_the_pairs_ride_as_mujocos_own_contacts(monkeypatch: pytest.MonkeyPatch) -> None:
    """At the nominal friction, the explicit pairs give the same bits as MuJoCo's dynamic
    contacts (a dead weight on each board for 0.2 s)."""
    scenario = Scenario(name="rest", duration=0.2)
    for board in ("hovershoes", "segway", "skateboard"):
        final = []
        for pairs in (True, False):
            if not pairs:
                monkeypatch.setattr(scene_module, "add_surface_pairs", lambda s, m, g: m)
            scene = build_scene(None, DEFAULT_PHYSICS_HZ, load_board(board), dead_weight=30.0)
            assert (scene.model.npair > 0) == pairs
            Simulation(scene, None, scenario).run()
            final.append(scene.data.qpos.copy())
        monkeypatch.undo()
        assert np.array_equal(final[0], final[1]), board


def _ride(mu: float) -> Any:
    scene = _scene("hovershoes")
    assert scene.robot is not None
    scenario = Scenario(
        name="ride",
        duration=1.2,
        commands=(CommandEvent(t=0.0, velocity=1.0, ramp=0.5),),
        changes=(ParameterChange(parameter="floor_friction", value=mu),),
    )
    return Simulation(scene, make_controller("pd", scene.robot, "hovershoes"), scenario).run()


def test_a_slippery_floor_changes_a_ride() -> None:
    """Cassie's PD ride on the Hovershoes: on mu = 1 it rolls forward; on mu = 0.05 the wheels
    spin out, the shoes run backwards and one noses into the floor (measured: 0.55 s)."""
    grip, ice = _ride(1.0), _ride(0.05)
    assert grip.status == "ok"
    assert grip.log["board_position"][-1, :, 0].min() > 0.05
    assert ice.fell
    ridden = min(len(grip.log["time"]), len(ice.log["time"]))
    gap = np.abs(grip.log["board_position"][:ridden] - ice.log["board_position"][:ridden])
    assert gap.max() > 0.1


def test_a_payload_is_one_more_rigid_body() -> None:
    """5 kg at (0.1, -0.05, 0.2) m in the base's frame: the rider's mass, centre of mass and
    joint-space inertia are those of the same robot with a welded 5 kg point mass there."""
    mass, offset = 5.0, np.array([0.1, -0.05, 0.2])
    scene = _scene("none")
    robot = scene.robot
    assert robot is not None
    sim = _simulation("none", {"parameter": "payload", "body": "base", "mass": mass,
                               "offset": tuple(offset)})  # fmt: skip
    model, data = scene.model, scene.data
    root = int(model.body_rootid[scene.base_body])
    scene.reset()
    mass0, com0 = model.body_subtreemass[root], data.subtree_com[root].copy()
    at = data.xpos[scene.base_body] + data.xmat[scene.base_body].reshape(3, 3) @ offset
    heavy = np.zeros((model.nv, model.nv))
    try:
        sim.changes.apply(0, data)
        assert model.body_subtreemass[root] == pytest.approx(mass0 + mass)
        expected_com = (mass0 * com0 + mass * at) / (mass0 + mass)
        np.testing.assert_allclose(data.subtree_com[root], expected_com, atol=1e-12)
        mujoco.mj_fullM(model, data, heavy)
    finally:
        sim.changes.restore()
    assert model.body_subtreemass[root] == pytest.approx(mass0)

    def spec_with_point_mass() -> mujoco.MjSpec:
        spec = robot.spec()
        spec.body(robot.params.base_body).add_body(
            name="payload",
            pos=offset,
            ipos=[0.0, 0.0, 0.0],  # set, or the spec puts the centre of mass at pos again
            mass=mass,
            inertia=[1e-12] * 3,
            explicitinertial=True,
        )
        return spec

    reference = dataclasses.replace(robot)
    object.__setattr__(reference, "spec", spec_with_point_mass)
    welded = build_scene(reference, DEFAULT_PHYSICS_HZ)
    welded.data.qpos[:] = data.qpos
    mujoco.mj_forward(welded.model, welded.data)
    expected = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(welded.model, welded.data, expected)
    np.testing.assert_allclose(heavy, expected, rtol=1e-9, atol=1e-9)


def test_a_late_change_waits_for_its_step_and_an_early_one_comes_first() -> None:
    """A shoe 1 kg heavier from t = 0 (seen at the first step), the floor at 0.2 from
    t = 0.1 s (seen from that step on, not before); both undone after the run."""
    scene = build_scene(None, DEFAULT_PHYSICS_HZ, load_board("hovershoes"), dead_weight=30.0)
    shoe = _id(scene, mujoco.mjtObj.mjOBJ_BODY, BOARD_PREFIX + "left_shoe")
    floor = _id(scene, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    mass0 = float(scene.model.body_mass[shoe])
    changes = (
        ParameterChange(parameter="floor_friction", t=0.1, value=0.2),
        ParameterChange(parameter="board_mass", body="left_shoe", value=mass0 + 1.0),
    )
    seen: list[tuple[float, float, float]] = []

    def watch(t: float, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        seen.append((t, float(model.body_mass[shoe]), float(model.geom_friction[floor, 0])))

    scenario = Scenario(name="late", duration=0.15, changes=changes)
    result = Simulation(scene, None, scenario, external=watch).run()
    assert result.status == "ok"
    times, masses, friction = np.array(seen).T
    assert np.all(masses == mass0 + 1.0)
    assert np.all(friction[times < 0.1 - 1e-9] == 1.0)
    assert np.all(friction[times >= 0.1 - 1e-9] == 0.2)
    assert scene.model.body_mass[shoe] == mass0 and scene.model.geom_friction[floor, 0] == 1.0


# --- refused -------------------------------------------------------------------------------


def _out_of_range(knob: str) -> list[tuple[str, float]]:
    spec = KNOBS[knob]
    bad: list[tuple[str, float]] = []
    if "value" in spec.forms or knob == "payload":
        field = "mass" if knob == "payload" else "value"
        low = spec.low if spec.low_open else spec.low - 1.0
        bad += [(field, low), (field, spec.high * 1.5), (field, math.nan), (field, math.inf)]
    if "scale" in spec.forms:
        top = spec.high if spec.forms == {"scale"} else SCALE_MAX
        bad += [("scale", 0.0), ("scale", -1.0), ("scale", top * 1.5), ("scale", math.nan)]
    return bad


_NAMES = {"body": "base", "gain": "pitch_kp", "joint": None}
BAD = [(knob, field, value) for knob in sorted(KNOBS) for field, value in _out_of_range(knob)]


def _toml(fields: dict[str, Any]) -> str:
    def literal(v: Any) -> str:
        if isinstance(v, bool):
            return str(v).lower()
        if isinstance(v, list):
            return "[" + ", ".join(literal(x) for x in v) + "]"
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, float) and not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)

    lines = [f"{k} = {literal(v)}" for k, v in fields.items() if v is not None]
    return 'name = "bad"\nduration = 1.0\n[[changes]]\n' + "\n".join(lines) + "\n"


@pytest.mark.parametrize(("knob", "field", "value"), BAD, ids=[f"{k}-{f}-{v}" for k, f, v in BAD])
def test_out_of_range_is_refused_in_one_line(
    tmp_path: Path, knob: str, field: str, value: float
) -> None:
    where = KNOBS[knob].where
    fields: dict[str, Any] = {"parameter": knob, field: value}
    if where is not None and KNOBS[knob].where_required:
        fields[where] = _NAMES[where]
    path = tmp_path / "bad.toml"
    path.write_text(_toml(fields))
    with pytest.raises(ConfigError) as refused:
        load_scenario_file(path)
    message = str(refused.value)
    assert "\n" not in message
    if math.isfinite(value):  # a range: the knob's own check names it
        assert "changes.0" in message and knob in message
        assert f"{field} = {value}" in message
    else:  # no number at all: the type refuses it, naming the field and the value
        assert f"changes.0.{field}" in message and "finite" in message
        assert str(value) in message


@pytest.mark.parametrize(
    ("fields", "words"),
    [
        ({"parameter": "floor_friction", "value": 0.5, "scale": 0.5}, "exactly one of"),
        ({"parameter": "floor_friction"}, "exactly one of"),
        ({"parameter": "motor_torque_limit", "value": 5.0}, "takes no value"),
        ({"parameter": "board_mass", "value": 3.0}, "needs a body"),
        ({"parameter": "floor_friction", "value": 0.5, "body": "deck"}, "takes no body"),
        ({"parameter": "payload", "body": "base", "mass": 2.0, "value": 1.0}, "takes no value"),
        ({"parameter": "payload", "body": "base", "mass": 2.0, "offset": [0, 0, 2]}, "offset"),
        ({"parameter": "floor_friction", "value": 0.5, "mass": 2.0}, "takes no mass"),
        ({"parameter": "gravity", "value": 1.0}, "valid: base_payload"),
        ({"parameter": "floor_friction", "value": "0.5"}, "changes.0.value"),
        ({"parameter": "floor_friction", "value": True}, "changes.0.value"),
        ({"parameter": "floor_friction", "t": "1", "value": 0.5}, "changes.0.t"),
        ({"parameter": "floor_friction", "t": math.inf, "value": 0.5}, "changes.0.t"),
        ({"parameter": "floor_friction", "t": math.nan, "value": 0.5}, "changes.0.t"),
        ({"parameter": "floor_friction", "t": -1.0, "value": 0.5}, "changes.0.t"),
        ({"parameter": "payload", "body": "base"}, "needs a mass"),
        ({"parameter": "payload", "mass": 1.0}, "needs a body"),
        ({"parameter": "payload", "body": 3, "mass": 1.0}, "changes.0.body"),
        ({"parameter": "payload", "body": "base", "mass": 1.0, "offset": [0, 0]}, "offset"),
        ({"parameter": "payload", "body": "base", "mass": 2.0, "offset": [0, 0, True]}, "offset"),
    ],
)
def test_malformed_changes_are_refused(tmp_path: Path, fields: dict, words: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(_toml(fields))
    with pytest.raises(ConfigError, match=words):
        load_scenario_file(path)


@pytest.mark.parametrize(
    ("board", "fields", "words"),
    [
        ("hovershoes", {"parameter": "board_mass", "body": "deck", "value": 1.0}, "left_shoe"),
        ("skateboard", {"parameter": "board_mass", "body": "left_shoe", "value": 1.0}, "deck"),
        ("segway", {"parameter": "payload", "body": "trunk", "mass": 1.0}, "left_foot"),
        ("hovershoes", {"parameter": "bushing_stiffness", "value": 10.0}, "no bushing_stiffness"),
        ("segway", {"parameter": "bushing_damping", "scale": 2.0}, "no bushing_damping"),
        ("skateboard", {"parameter": "firmware_gain", "gain": "pitch_kp", "value": 1.0}, "none"),
        ("segway", {"parameter": "firmware_gain", "gain": "tilt", "value": 1.0}, "yaw_rate_kp"),
        ("none", {"parameter": "tyre_friction", "value": 0.5}, "no board wheel"),
        ("none", {"parameter": "wheel_radius", "value": 0.05}, "no board"),
        ("none", {"parameter": "joint_damping", "joint": "knee", "value": 1.0}, "left_knee"),
        ("segway", {"parameter": "wheel_radius", "scale": 5.0}, r"outside \(0, 0.5\] m"),
        ("hovershoes", {"parameter": "wheel_radius", "value": 0.06}, "clear the top of the wheel"),
        ("segway", {"parameter": "firmware_gain", "gain": "pitch_kp", "value": 0.0}, "greater"),
    ],
)
def test_changes_that_do_not_fit_the_pair_are_refused_before_the_ride(
    board: str, fields: dict, words: str
) -> None:
    with pytest.raises(ConfigError, match=words) as refused:
        _simulation(board, fields)
    assert "\n" not in str(refused.value)
    assert "changes[0]" in str(refused.value)
    with pytest.raises(ConfigError, match=words):  # checked alone, before anything is made
        ScheduledChanges(_scene(board), (ParameterChange(**fields),), None, None, "check")


def test_a_dead_weight_has_no_motors() -> None:
    scene = build_scene(None, DEFAULT_PHYSICS_HZ, load_board("segway"), dead_weight=30.0)
    scenario = Scenario(
        name="weak", duration=0.1,
        changes=(ParameterChange(parameter="motor_torque_limit", scale=0.5),),
    )  # fmt: skip
    with pytest.raises(ConfigError, match="no motors"):
        Simulation(scene, None, scenario)


def test_the_cli_refuses_a_change_that_does_not_fit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bushing.toml"
    path.write_text(_toml({"parameter": "bushing_stiffness", "value": 10.0}))
    code = main(
        ["sim", "--robot", "cassie", "--board", "hovershoes", "--controller", "pd",
         "--scenario", str(path), "--out", str(tmp_path / "out"), "--no-plots"]
    )  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err.startswith("ridempc: error:") and "\n" not in err
    assert "bushing_stiffness" in err and "hovershoes" in err


def test_the_readme_table_states_each_knobs_unit_and_range() -> None:
    readme = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    for name, knob in KNOBS.items():
        low, high = knob.allowed().split(" ")[:2]
        unit = knob.unit if knob.unit != "gain's" else "the gain's"
        assert f"| `{name}` | {unit} | {low} {high} |" in readme, name


def test_the_documented_example_loads_and_fits_cassie_on_the_hovershoes() -> None:
    import textwrap
    import tomllib

    import ridempc.scenarios.scenario as scenario_module

    doc = scenario_module.__doc__ or ""
    example = textwrap.dedent(doc.split("Example::")[1].split("The other knobs")[0])
    scenario = Scenario(**tomllib.loads(example))
    assert len(scenario.changes) == 4
    scene = _scene("hovershoes")
    assert scene.robot is not None
    Simulation(scene, make_controller("stand", scene.robot, "hovershoes"), scenario)


@pytest.mark.parametrize(
    ("board", "radius"), [("hovershoes", 0.04), ("segway", 0.15), ("skateboard", 0.035)]
)
def test_a_new_wheel_radius_keeps_the_deck_and_the_wheels_on_the_ground(
    board: str, radius: float
) -> None:
    """The builder keeps the deck at its height; the axle moves, the wheels still touch z = 0."""
    sim = _simulation(board, {"parameter": "wheel_radius", "value": radius})
    scene = sim.scene
    assert scene.board is not None
    sites = [
        _id(scene, mujoco.mjtObj.mjOBJ_SITE, BOARD_PREFIX + n)
        for n in scene.board.params.platform_sites
    ]
    scene.reset()
    deck = scene.data.site_xpos[sites, 2].copy()
    try:
        sim.changes.apply(0, scene.data)
        np.testing.assert_allclose(scene.data.site_xpos[sites, 2], deck, atol=1e-12)
        assert scene_module._lowest_point(
            scene.model, scene.data, scene.board_ground_bodies
        ) == pytest.approx(0.0, abs=1e-12)
    finally:
        sim.changes.restore()


def test_a_slippery_deck_governs_the_feet_on_it() -> None:
    """The Hovershoes' decks (1.5) at 0.5: each foot's pair with a deck grips at 0.5."""
    sim = _simulation("hovershoes", {"parameter": "deck_friction", "value": 0.5})
    scene, model = sim.scene, sim.scene.model
    feet = {
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] in scene.foot_bodies and model.geom_contype[g]
    }
    try:
        sim.changes.apply(0, scene.data)
        on_deck = [  # MuJoCo orders each pair's geoms by body
            p
            for p in range(model.npair)
            if {model.pair_geom1[p], model.pair_geom2[p]} & scene.deck_geoms
            and {model.pair_geom1[p], model.pair_geom2[p]} & feet
        ]
        assert len(on_deck) == 2 * len(feet)  # each foot with each shoe's deck
        assert np.allclose(model.pair_friction[on_deck, 0], 0.5)
    finally:
        sim.changes.restore()
    assert np.allclose(model.pair_friction[on_deck, 0], 1.5)


def test_successive_torque_limits_are_each_a_scale_of_the_description() -> None:
    """0.5 at t = 0, 0.8 at t = 0.1 s: the peak torque is 0.5, then 0.8 times the motor's
    own, and the motor's own after the run (``scale_torque_limit`` multiplies what is)."""
    sim = _simulation(
        "skateboard",
        {"parameter": "motor_torque_limit", "scale": 0.5},
        {"parameter": "motor_torque_limit", "t": 0.1, "scale": 0.8},
        duration=0.1,
    )
    peak = _peak_torque(sim)
    tick = round(0.1 * sim.scene.physics_hz)
    try:
        assert sim.changes.apply(0, sim.scene.data)
        assert _peak_torque(sim) == pytest.approx(0.5 * peak)
        assert sim.changes.apply(tick, sim.scene.data)
        assert _peak_torque(sim) == pytest.approx(0.8 * peak)
    finally:
        sim.changes.restore()
    assert _peak_torque(sim) == pytest.approx(peak)
