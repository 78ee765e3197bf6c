"""The Segway (miniPro class): its build, firmware, reduced model and parameter checks.

- it rests on its wheels with the platform site on the platform's top surface, holds two
  Cassie feet side by side (0.27 m apart) clear of the knee-bar column;
- with a dead weight of Cassie's mass it stays balanced, also after a shove;
- shifting the weight forward (its centre of mass placed forward, or a forward lean torque)
  accelerates it forward, backward backward, and the speed is held near the top speed;
- pushing the knee bar to the left (+y) turns it left (positive yaw rate), to the right right;
- the identified reduced model predicts held-out trials (NRMSE reported and bounded) and
  agrees with the ``[reduced]`` table of ``board.toml``; its dynamics run under CasADi;
- a broken parameter file is refused naming the field;
- Pinocchio and MuJoCo read the same board (mass, centre of mass, mass matrix).
"""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from ridempc.boards import load_board, load_board_file
from ridempc.boards.segway import identify
from ridempc.boards.segway.experiments import piecewise, run_trial
from ridempc.boards.segway.parameters import SegwayParameters
from ridempc.boards.segway.reduced import segway_dynamics
from ridempc.errors import ConfigError
from ridempc.robots import load_robot
from ridempc.robots.pinocchio_model import CoordinateMap
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from tests.helpers import scenario

BOARD = load_board("segway")
PARAMS = BOARD.params
assert isinstance(PARAMS, SegwayParameters)
RIDER_MASS = load_robot(PARAMS.dead_weight_robot).mass
CASSIE_FEET_APART = 0.27  # [m] between the feet's centre lines, riding a Segway


def _zero(t: float) -> float:
    return 0.0


def _pitch(quat_wxyz: np.ndarray) -> float:
    w, x, y, z = quat_wxyz
    return float(np.arcsin(2.0 * (w * y - z * x)))


# ---------------------------------------------------------------------------- the build


def test_rests_on_its_wheels_with_the_platform_site_on_top() -> None:
    model = BOARD.mj_model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert BOARD.mass == pytest.approx(12.8, abs=1e-9)
    for side in ("left", "right"):
        tyre = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{side}_tyre")
        assert data.geom_xpos[tyre, 2] - PARAMS.wheel_radius == pytest.approx(0.0, abs=1e-9)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "platform")
    platform = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "platform")
    top = data.geom_xpos[platform, 2] + model.geom_size[platform, 2]
    assert data.site_xpos[site, 2] == pytest.approx(top, abs=1e-9)
    assert data.site_xpos[site, 2] == pytest.approx(PARAMS.platform_height, abs=1e-9)
    assert np.allclose(data.site_xpos[site, :2], 0.0)


def test_platform_holds_both_cassie_feet_clear_of_the_column() -> None:
    cassie = load_robot("cassie").mj_model
    foot = mujoco.mj_name2id(cassie, mujoco.mjtObj.mjOBJ_GEOM, "left_foot")
    radius, half_length = cassie.geom_size[foot, :2]
    y = CASSIE_FEET_APART / 2
    assert y + radius < PARAMS.platform_width / 2  # on the platform, off the wheels
    assert y - radius > PARAMS.knee_bar_radius + 0.05  # clear of the column
    assert 2 * (half_length + radius) <= PARAMS.platform_length
    bar_height = PARAMS.knee_bar_height
    assert 0.45 <= bar_height <= 0.55  # Cassie's knee height over the platform


# ---------------------------------------------------------------------- with a dead weight


def test_dead_weight_stays_balanced_also_after_a_shove() -> None:
    shove = piecewise([1.0, 1.2], [60.0, 0.0])  # [N] forward on the weight
    scene = build_scene(None, 1500, board=BOARD, dead_weight=RIDER_MASS)

    def external(t: float, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        data.xfrc_applied[scene.base_body, 0] += shove(t)

    result = Simulation(scene, None, scenario(5.0), external=external).run()
    assert result.status == "ok", result.fall_reason
    quats = result.log["board_quaternion"][:, 0]
    pitch = np.array([_pitch(q) for q in quats])
    assert np.max(np.abs(pitch)) < 0.1
    last = result.log["time"] > 4.0
    assert np.max(np.abs(pitch[last])) < 0.01
    assert np.max(np.abs(result.log["yaw_rate"])) < 1e-3
    speed = result.log["firmware_speed"]
    assert abs(speed[-1]) < abs(speed[result.log["time"] >= 1.3][0])  # coming to rest


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_weight_forward_accelerates_forward_and_the_speed_is_limited(direction: float) -> None:
    offset = (0.03 * direction, 0.0)  # [m] the weight's centre of mass ahead of the axle
    scene = build_scene(None, 1500, board=BOARD, dead_weight=RIDER_MASS, foot_offset=offset)
    result = Simulation(scene, None, scenario(8.0)).run()
    assert result.status == "ok", result.fall_reason
    t, speed = result.log["time"], direction * result.log["forward_velocity"]
    at = {s: float(speed[np.argmin(np.abs(t - s))]) for s in (1.0, 2.0, 3.0)}
    assert 0.3 < at[1.0] < at[2.0] < at[3.0]
    assert np.max(speed) < 1.1 * PARAMS.top_speed


@pytest.mark.parametrize("lean", [5.0, -5.0])
def test_leaning_forward_accelerates_forward(lean: float) -> None:
    trial = run_trial(BOARD, RIDER_MASS, 2.5, piecewise([0.5], [lean]), _zero)
    assert not trial.fell
    speed = np.sign(lean) * trial.speed
    assert speed[-1] > 0.3
    assert speed[-1] > speed[len(speed) // 2] > 0.0


@pytest.mark.parametrize("push", [6.0, -6.0])  # [N m] positive = knee bar pushed to the left
def test_knee_bar_turns_the_matching_way(push: float) -> None:
    trial = run_trial(BOARD, RIDER_MASS, 2.0, _zero, piecewise([0.5], [push]))
    assert not trial.fell
    late = trial.time > 1.0
    assert np.all(np.sign(push) * trial.knee_bar[late] > 0.05)  # the sensor: + = left
    assert np.all(np.sign(push) * trial.yaw_rate[late] > 0.3)  # + = turning left
    assert np.sign(push) * (trial.psi[-1] - trial.psi[0]) > 0.3


# ------------------------------------------------------------------------ reduced model


@pytest.fixture(scope="module")
def identified():
    return identify(BOARD)


def test_identified_model_predicts_held_out_trials(identified) -> None:
    print("\n" + identified.table())  # shown with pytest -s
    fit = identified.fit
    for signal in ("theta", "speed", "yaw_rate"):
        assert fit[f"{signal}_nrmse"] < 0.05, (signal, fit)
        assert fit[f"{signal}_r2"] > 0.98, (signal, fit)
    assert fit["position_nrmse"] < 0.05
    assert identified.trials_held_out >= 2
    # the speed and pitch-rate terms of the drive force are what the paper's form lacks
    assert identified.extra["paper_form_speed_nrmse"] > 2 * fit["speed_nrmse"]


def test_board_file_holds_the_identified_model(identified) -> None:
    stored = PARAMS.reduced
    assert stored is not None, "board.toml has no [reduced] table"
    for name, value in identified.parameters.items():
        assert getattr(stored, name) == pytest.approx(value, rel=0.05), name


def test_reduced_dynamics_run_under_casadi() -> None:
    casadi = pytest.importorskip("casadi")
    stored = PARAMS.reduced
    assert stored is not None
    x = casadi.SX.sym("x", 7)
    u = casadi.SX.sym("u", 2)
    f = casadi.Function("f", [x, u], [casadi.vertcat(*segway_dynamics(x, u, stored, casadi))])
    rng = np.random.default_rng(3)
    state, control = rng.normal(size=7), rng.normal(size=2)
    expected = np.array(segway_dynamics(state, control, stored))
    assert np.allclose(np.array(f(state, control)).ravel(), expected)


# ------------------------------------------------------------------------- bad inputs


def _broken_copy(tmp_path: Path, edit) -> Path:
    folder = tmp_path / "segway"
    folder.mkdir()
    path = folder / "board.toml"
    shutil.copy(BOARD.folder / "board.toml", path)
    text = path.read_text()
    path.write_text(edit(text))
    return path


def _set(field: str, value: str):
    def edit(text: str) -> str:
        lines = text.splitlines()
        hits = [i for i, line in enumerate(lines) if line.split("=")[0].strip() == field]
        assert len(hits) == 1, field
        lines[hits[0]] = f"{field} = {value}"
        return "\n".join(lines) + "\n"

    return edit


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("wheel_radius", "0.0"),
        ("chassis_mass", "-6.6"),
        ("knee_bar_range", "95.0"),
        ("motor_torque_limit", "-40.0"),
        ("pitch_kp", "-250.0"),
        ("platform_width", "0.5"),
        ("platform_thickness", "0.2"),
    ],
)
def test_non_physical_value_is_refused_naming_the_field(
    tmp_path: Path, field: str, value: str
) -> None:
    path = _broken_copy(tmp_path, _set(field, value))
    with pytest.raises(ConfigError, match=field):
        load_board_file(path)


def test_missing_value_is_refused_naming_the_field(tmp_path: Path) -> None:
    path = _broken_copy(
        tmp_path,
        lambda text: "\n".join(
            line for line in text.splitlines() if not line.startswith("track_width")
        ),
    )
    with pytest.raises(ConfigError, match="track_width"):
        load_board_file(path)


def test_board_file_parses_as_a_segway() -> None:
    with open(BOARD.folder / "board.toml", "rb") as stream:
        raw = tomllib.load(stream)
    assert raw["kind"] == "segway"
    assert isinstance(load_board_file(BOARD.folder / "board.toml").params, SegwayParameters)


# ------------------------------------------------------------------ Pinocchio vs MuJoCo


def test_pinocchio_and_mujoco_agree(tmp_path: Path) -> None:
    path = tmp_path / "segway.xml"
    path.write_text(BOARD.mjcf())
    pmodel = pin.buildModelFromMJCF(str(path))
    pdata = pmodel.createData()
    model = BOARD.mj_model
    data = mujoco.MjData(model)
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    assert list(pmodel.names)[1:] == names
    assert (pmodel.nq, pmodel.nv) == (model.nq, model.nv)
    assert pin.computeTotalMass(pmodel) == pytest.approx(BOARD.mass, rel=1e-9)
    coords = CoordinateMap.from_mujoco(model)
    rng = np.random.default_rng(20261122)
    chassis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "chassis")
    for _ in range(10):
        qpos = model.qpos0.copy()
        qpos[:3] = rng.uniform(-1.0, 1.0, 3)
        quat = rng.normal(size=4)
        qpos[3:7] = quat / np.linalg.norm(quat)
        qpos[7:9] = rng.uniform(-np.pi, np.pi, 2)
        qpos[9] = rng.uniform(*model.jnt_range[3])
        data.qpos[:] = qpos
        mujoco.mj_forward(model, data)
        q = coords.qpos_to_pinocchio(qpos)
        com = pin.centerOfMass(pmodel, pdata, q)
        assert np.allclose(com, data.subtree_com[chassis], atol=1e-9)
        mass_mj = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, mass_mj)
        transform = coords.velocity_map(qpos)
        pin.crba(pmodel, pdata, q)
        mass_pin = np.triu(pdata.M) + np.triu(pdata.M, 1).T
        assert np.allclose(mass_pin, transform.T @ mass_mj @ transform, atol=1e-9)
