"""The skateboard: geometry, steering by leaning (eqs. 11-14), identified roll model (eqs. 6-7),
no-op firmware, checked parameter file, and Pinocchio reading the same description as MuJoCo."""

from __future__ import annotations

import math
import re
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from ridempc.boards import load_board, load_board_file
from ridempc.boards.skateboard.experiments import (
    RollHold,
    SteeringTrial,
    run_steering_trial,
    skateboard_scene,
)
from ridempc.boards.skateboard.firmware import PassiveFirmware
from ridempc.boards.skateboard.identify import identify
from ridempc.boards.skateboard.model import DECK, PLATFORM_SITE, TRUCKS, WHEELS
from ridempc.boards.skateboard.reduced import (
    board_length,
    dubins_rates,
    roll_acceleration,
    steer_gain,
    steering_angle_tangent,
    steering_axle_distances,
    yaw_rate,
)
from ridempc.errors import ConfigError
from ridempc.robots.pinocchio_model import CoordinateMap
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from tests.helpers import scenario

NAME = "skateboard"
DEAD_WEIGHT = 8.9  # [kg] CyberDog2
STEER_TOLERANCE = 0.15  # eq. (14) within 15 %


@pytest.fixture(scope="module")
def board():
    return load_board(NAME)


@pytest.fixture(scope="module")
def scene(board):
    return skateboard_scene(board, DEAD_WEIGHT)


@pytest.fixture(scope="module")
def identified(board):
    return identify(board)


# --- geometry --------------------------------------------------------------------------


def test_board_rests_on_its_wheels_with_the_platform_on_top(board) -> None:
    model = board.mj_model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    params = board.params
    assert board.mass == pytest.approx(
        params.deck_mass + 2 * params.truck_mass + 4 * params.wheel_mass
    )
    for wheel in (*WHEELS[0], *WHEELS[1]):
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, wheel)
        assert data.geom_xpos[geom, 2] - model.geom_size[geom, 0] == pytest.approx(0.0, abs=1e-12)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, PLATFORM_SITE)
    assert data.site_xpos[site] == pytest.approx([0.0, 0.0, params.height])
    top = max(
        data.geom_xpos[g, 2] + model.geom_size[g, 2]
        for g in range(model.ngeom)
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX and model.geom_contype[g]
    )
    assert top == pytest.approx(params.height)
    for truck, rake in zip(TRUCKS, (params.rake_front, params.rake_rear), strict=True):
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, truck)
        tilt = math.degrees(math.acos(model.jnt_axis[joint][2]))
        assert tilt == pytest.approx(rake)
    assert model.nu == 0  # no motors: the skateboard has no electronics


def _truck_steer(board, roll: float, truck: int) -> float:
    """Axle yaw [rad] with the deck rolled by ``roll`` and the truck turned so that both of
    its wheels touch the ground (pure kinematics, found by bisection)."""
    model = board.mj_model
    data = mujoco.MjData(model)
    joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, TRUCKS[truck])
    left, right = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, w) for w in WHEELS[truck])
    data.qpos[3:7] = [math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0]

    def height_difference(theta: float) -> float:
        data.qpos[model.jnt_qposadr[joint]] = theta
        mujoco.mj_kinematics(model, data)
        return float(data.xpos[left, 2] - data.xpos[right, 2])

    low, high = -1.0, 1.0
    for _ in range(60):
        mid = 0.5 * (low + high)
        if np.sign(height_difference(mid)) == np.sign(height_difference(low)):
            low = mid
        else:
            high = mid
    height_difference(0.5 * (low + high))
    axle = data.xpos[left] - data.xpos[right]
    return math.atan2(-axle[0], axle[1])


@pytest.mark.parametrize("roll", [0.05, 0.1, 0.2])
def test_truck_geometry_gives_eq_11(board, roll: float) -> None:
    """tan(delta) = sin(phi) cot(gamma): front axle steers into the lean, rear out of it."""
    for truck, rake, sign in ((0, board.params.rake_front, 1.0), (1, board.params.rake_rear, -1.0)):
        expected = -sign * steering_angle_tangent(roll, math.radians(rake))
        assert math.tan(_truck_steer(board, roll, truck)) == pytest.approx(expected, rel=1e-6)


# --- eq. (14) against the simulation -------------------------------------------------------


@pytest.mark.parametrize("speed", [0.6, 1.2, 1.8])
@pytest.mark.parametrize("roll", [0.05, -0.1])
def test_leaning_turns_at_the_rate_of_eq_14(board, scene, speed: float, roll: float) -> None:
    """Loaded deck pushed to a speed, roll held by a torque on the deck: steady yaw rate."""
    record = run_steering_trial(
        scene, SteeringTrial("hold", speed, RollHold(1.0, roll), duration=2.5)
    ).window(1.8)
    measured = float(np.mean(record.yaw_rate))
    gain = steer_gain(board.params)  # (cot g_f + cot g_r) / L of its rake angles
    predicted = float(np.mean(yaw_rate(record.speed, record.roll, gain)))
    assert np.mean(record.speed) == pytest.approx(speed, rel=0.1)
    assert np.mean(record.roll) == pytest.approx(roll, rel=0.1)
    assert np.sign(measured) == -np.sign(roll)  # leaning right (roll > 0) turns right
    assert measured == pytest.approx(predicted, rel=STEER_TOLERANCE)


# --- identified reduced model --------------------------------------------------------------


def test_identified_model_predicts_held_out_trials(board, identified) -> None:
    fit = identified.fit
    print("\n" + identified.table())
    assert identified.trials_held_out >= 2
    assert fit["roll_nrmse"] < 0.05 and fit["roll_r2"] > 0.95
    assert fit["loaded_roll_nrmse"] < 0.05
    assert fit["yaw_rate_nrmse"] < 0.05 and fit["yaw_rate_r2"] > 0.95
    assert fit["position_error_per_m"] < 0.05
    assert abs(fit["steer_gain_vs_geometry"]) < 0.05
    assert identified.extra["wall_time"] < 60.0


def test_board_file_holds_the_identified_model(board, identified) -> None:
    reduced = board.params.reduced
    assert reduced is not None
    for name, value in identified.parameters.items():
        assert getattr(reduced, name) == pytest.approx(value, rel=0.05), name


def test_reduced_model_runs_on_casadi() -> None:
    casadi = pytest.importorskip("casadi")
    heading, speed, roll, rate, torque = (casadi.SX.sym(n) for n in "hvrwt")
    gain = 1.0 / board_length(math.radians(40.0), math.radians(50.0), 0.49)
    rates = casadi.Function(
        "f", [heading, speed, roll], list(dubins_rates(heading, speed, roll, gain, casadi))
    )
    x_dot, y_dot, yaw = (float(v) for v in rates(0.3, 1.2, 0.1))
    assert (x_dot, y_dot) == pytest.approx((1.2 * math.cos(0.3), 1.2 * math.sin(0.3)))
    l_f, l_r = steering_axle_distances(math.radians(40.0), math.radians(50.0), 0.49)
    assert l_f + l_r == pytest.approx(0.49)
    tan_f = steering_angle_tangent(0.1, math.radians(40.0))
    tan_r = steering_angle_tangent(0.1, math.radians(50.0))
    assert yaw == pytest.approx(-1.2 * (tan_f + tan_r) / 0.49)  # omega = -v (tan d_f + tan d_r) / L
    accel = casadi.Function(
        "a", [roll, rate, torque], [roll_acceleration(roll, rate, torque, 0.1, 50.0, 2.0)]
    )
    assert float(accel(0.1, 0.5, 3.0)) == pytest.approx((3.0 - 5.0 - 1.0) / 0.1)


# --- firmware --------------------------------------------------------------------------


@pytest.mark.parametrize("rate", [1500.0, 500.0, 30.0])
def test_firmware_is_a_passive_no_op(board, rate: float) -> None:
    params = board.params.model_copy(update={"firmware_hz": rate})
    moved = type(board)(params=params, folder=board.folder)
    scene = build_scene(None, 1500, board=moved, dead_weight=DEAD_WEIGHT)
    simulation = Simulation(scene, None, scenario(0.2))
    assert isinstance(simulation.firmware, PassiveFirmware)
    assert simulation.firmware.rate_hz == rate
    before = scene.data.ctrl.copy()
    result = simulation.run()
    assert result.status == "ok"
    assert scene.model.nu == 0 and np.array_equal(scene.data.ctrl, before)
    assert simulation.firmware.diagnostics() == {}


# --- parameter file --------------------------------------------------------------------


BAD_VALUES = [
    ("deck_mass", "-1.0", "deck_mass"),
    ("wheel_radius", "0.0", "wheel_radius"),
    ("rake_front", "95.0", "rake_front"),
    ("rake_rear", "0.0", "rake_rear"),
    ("bushing_stiffness", "-12.0", "bushing_stiffness"),
    ("roll_limit", "0.0", "roll_limit"),
    ("height", "0.05", "height"),
    ("roll_stiffness", "-47.8", "reduced.roll_stiffness"),
    ("wheelbase", None, "wheelbase"),
]


@pytest.mark.parametrize(("field", "value", "named"), BAD_VALUES)
def test_bad_parameter_is_refused_by_name(board, tmp_path: Path, field, value, named) -> None:
    text = (board.folder / "board.toml").read_text()
    line = re.compile(rf"^{field} = .*$", re.MULTILINE)
    assert line.search(text), field
    broken = line.sub("" if value is None else f"{field} = {value}", text)
    path = tmp_path / NAME / "board.toml"
    path.parent.mkdir()
    path.write_text(broken)
    with pytest.raises(ConfigError, match=re.escape(named)):
        load_board_file(path)


# --- Pinocchio reads the same description --------------------------------------------------


def test_pinocchio_and_mujoco_agree(board, tmp_path: Path) -> None:
    path = tmp_path / "skateboard.xml"
    path.write_text(board.mjcf())
    pmodel = pin.buildModelFromMJCF(str(path))
    pdata = pmodel.createData()
    model = mujoco.MjModel.from_xml_path(str(path))  # both engines read the same text
    data = mujoco.MjData(model)
    coords = CoordinateMap.from_mujoco(model)
    assert (pmodel.nq, pmodel.nv) == (model.nq, model.nv)
    assert pin.computeTotalMass(pmodel) == pytest.approx(board.mass, rel=1e-9)
    bodies = [DECK, *TRUCKS, *WHEELS[0], *WHEELS[1]]
    frames = [pmodel.getFrameId(b, pin.FrameType.BODY) for b in bodies]
    platform = pmodel.getFrameId(PLATFORM_SITE)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, PLATFORM_SITE)
    rng = np.random.default_rng(20261122)
    for _ in range(10):
        qpos = model.qpos0.copy()
        qpos[:3] = rng.uniform(-1.0, 1.0, 3)
        quat = rng.normal(size=4)
        qpos[3:7] = quat / np.linalg.norm(quat)
        for j in range(1, model.njnt):
            low, high = model.jnt_range[j] if model.jnt_limited[j] else (-np.pi, np.pi)
            qpos[model.jnt_qposadr[j]] = rng.uniform(low, high)
        data.qpos[:] = qpos
        mujoco.mj_forward(model, data)
        q = coords.qpos_to_pinocchio(qpos)
        assert pin.centerOfMass(pmodel, pdata, q) == pytest.approx(data.subtree_com[1], abs=1e-9)
        mass_mj = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, mass_mj)
        transform = coords.velocity_map(qpos)
        pin.crba(pmodel, pdata, q)
        mass_pin = np.triu(pdata.M) + np.triu(pdata.M, 1).T
        assert mass_pin == pytest.approx(transform.T @ mass_mj @ transform, abs=1e-9)
        pin.framesForwardKinematics(pmodel, pdata, q)
        for body, frame in zip(bodies, frames, strict=True):
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
            assert pdata.oMf[frame].translation == pytest.approx(data.xpos[b], abs=1e-9)
        assert pdata.oMf[platform].translation == pytest.approx(data.site_xpos[site], abs=1e-9)
