"""The general disturbance observer (ridempc.mpc.disturbance) alone, on a synthetic linear
system: a point mass whose model misses a constant acceleration. The observer finds it from
the plans' one-step prediction errors, and an MPC that takes it as a drift holds its
reference without an offset, where the same MPC without it settles off."""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from ridempc.boards.canonical import BoardState
from ridempc.errors import ConfigError
from ridempc.mpc.disturbance import DisturbanceObserver, disturbance_rows
from ridempc.mpc.plan import Plan
from ridempc.mpc.problem import MPC_STEP, build_linear_model, linearize
from ridempc.pair_description import read_pair_file
from ridempc.paths import pairs_dir

TICK = 0.03  # [s] the rider's MPC tick (15 ticks of 2 ms), a little under the 1/30 s step
MASS = 40.0  # [kg] a rider's
HIDDEN = 0.8  # [m/s^2] the acceleration the model misses (a 3 kg payload's weight's share)
NAMES = ("com_x", "vx")


def _point_mass() -> ca.Function:
    """:math:`\\dot p = v`, :math:`\\dot v = u / m` (one input, a force [N])."""
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 1)
    return ca.Function("rates", [x, u, p], [ca.vertcat(x[1], u[0] / MASS)])


def _mpc_step(model, x0: np.ndarray, drift: np.ndarray | None, horizon: int = 12) -> Plan:
    """An unconstrained MPC (batch least squares) holding ``com_x`` at 0 on the model
    :math:`x_{k+1} = A x_k + B u_k + c_k` from :func:`linearize` with ``drift``."""
    u_ref, p_ref = np.zeros((horizon, 1)), np.zeros((horizon, 1))
    dyn = linearize(model, x0, u_ref, p_ref, MPC_STEP, drift)
    n, m = 2, 1
    # states x_1..x_N = F x0 + G u + h
    big_f = np.zeros((horizon * n, n))
    big_g = np.zeros((horizon * n, horizon * m))
    big_h = np.zeros(horizon * n)
    state_map, offset = np.eye(n), np.zeros(n)
    for k in range(horizon):
        a, b, c = dyn.A[k], dyn.B[k], dyn.c[k]
        state_map, offset = a @ state_map, a @ offset + c
        big_f[k * n : (k + 1) * n] = state_map
        big_h[k * n : (k + 1) * n] = offset
        for j in range(k + 1):
            prod = b
            for i in range(j + 1, k + 1):
                prod = dyn.A[i] @ prod
            big_g[k * n : (k + 1) * n, j * m : (j + 1) * m] = prod
    weights = np.tile([1.0 / 0.01**2, 1.0 / 0.05**2], horizon)  # Bryson: 1 cm, 5 cm/s
    r = 1.0 / 40.0**2  # 40 N
    free = big_f @ x0 + big_h
    lhs = big_g.T @ (weights[:, None] * big_g) + r * np.eye(horizon * m)
    u = np.linalg.solve(lhs, -big_g.T @ (weights * free))
    states = np.vstack([x0, (free + big_g @ u).reshape(horizon, n)])
    inputs = u.reshape(horizon, m)
    return Plan(states, inputs, inputs[0].copy(), "solved", 0.0, False)


def _truth(x: np.ndarray, force: float, duration: float) -> np.ndarray:
    """The point mass with the acceleration the model misses, ``force`` held [N]."""
    a = force / MASS + HIDDEN
    return np.array([x[0] + x[1] * duration + 0.5 * a * duration**2, x[1] + a * duration])


def _ride(observer: DisturbanceObserver | None, ticks: int = 100) -> np.ndarray:
    model = build_linear_model(_point_mass())
    x, plan = np.array([0.02, 0.0]), None
    for j in range(ticks):
        now = j * TICK
        drift = None
        if observer is not None:
            observer.update(x, plan, now, TICK, MPC_STEP)
            drift = observer.drift(2)
        plan = _mpc_step(model, x, drift)
        x = _truth(x, float(plan.first_input[0]), TICK)
    return x


def test_it_finds_a_constant_disturbance_and_the_loop_has_no_offset() -> None:
    """Within 3 s (100 ticks, ten time constants of 0.3 s) the estimate is within 2 % of
    the hidden acceleration and the mass stands at its reference within 1 mm; the same MPC
    without the observer stands off by the force its weights trade for the offset."""
    rows, angular = disturbance_rows(NAMES, {}, ("horizontal",))
    assert rows == (1,) and angular == (False,)
    observer = DisturbanceObserver(rows, angular, 0.3, 3.0, 10.0)
    x = _ride(observer)
    assert observer.estimate[0] == pytest.approx(HIDDEN, rel=0.02)
    assert abs(x[0]) < 1e-3
    assert abs(x[1]) < 1e-3
    offset = _ride(None)[0]
    assert offset > 0.005  # [m] pushed forward by the hidden acceleration


def test_it_holds_where_it_cannot_read_and_stays_within_its_bounds() -> None:
    """No plan, a held tick or a plan older than its step leave the estimate alone; a
    wild error (a fall) winds it only to its bound."""
    observer = DisturbanceObserver((1,), (False,), 0.1, 3.0, 10.0)
    wrong = Plan(np.array([[0.0, 0.0], [0.0, 0.0]]), np.zeros((1, 1)), np.zeros(1), "", 0, False)
    x = np.array([0.0, 5.0])
    observer.update(x, None, 0.0, TICK, MPC_STEP)
    observer.update(x, wrong, TICK, TICK, MPC_STEP, hold=True)
    observer.update(x, wrong, 2 * TICK, 2 * MPC_STEP, MPC_STEP)
    assert observer.estimate[0] == 0.0
    observer.update(x, wrong, 3 * TICK, TICK, MPC_STEP)
    assert observer.estimate[0] == 3.0
    observer.update(np.array([0.0, np.nan]), wrong, 4 * TICK, TICK, MPC_STEP)
    assert observer.estimate[0] == 3.0
    observer.reset()
    assert observer.estimate[0] == 0.0


def test_the_planar_velocity_is_turned_into_the_frame_that_moved() -> None:
    """A frame turned by 90 degrees since the plan reads its forward velocity sideways."""
    observer = DisturbanceObserver((0, 1), (False, False), 0.3, 3.0, 10.0, planar=(0, 1))
    plan = Plan(np.array([[1.0, 0.0], [1.0, 0.0]]), np.zeros((1, 1)), np.zeros(1), "", 0, False)
    turned = observer.predicted(plan, TICK, MPC_STEP, np.pi / 2)
    np.testing.assert_allclose(turned, [0.0, -1.0], atol=1e-12)


def test_the_rows_come_from_canonical_names() -> None:
    """The rider's velocity rows by their canonical names, the board's rates by quantity."""
    names = ("com_x", "vx", "vy", "vz", "wx", "wy", "wz", "deck_pitch", "deck_rate", "deck_v")
    board = {
        "deck_pitch": BoardState(0, "pitch"),
        "deck_rate": BoardState(0, "pitch_rate"),
        "deck_v": BoardState(0, "speed"),
    }
    rows, angular = disturbance_rows(names, board)
    assert rows == (1, 2, 3, 4, 5, 6, 8, 9)
    assert angular == (False, False, False, True, True, True, True, False)
    assert disturbance_rows(names, board, ("board",))[0] == (8, 9)
    with pytest.raises(ValueError, match="unknown disturbance rows 'legs'"):
        disturbance_rows(names, board, ("legs",))


def test_a_bad_stage_names_the_file_and_the_field(tmp_path: Path) -> None:
    text = (pairs_dir() / "cassie-segway.toml").read_text().split("[stages.disturbance]")[0]
    stage = "\n[stages.disturbance]\ntime_constant = 0.3\nmax_linear = 3.0\nmax_angular = 10.0\n"
    bad = text + stage + 'rows = ["legs"]\n'
    path = tmp_path / "cassie-segway.toml"
    path.write_text(bad)
    with pytest.raises(ConfigError, match="field 'stages.disturbance.rows.0'") as caught:
        read_pair_file(path)
    assert "\n" not in str(caught.value)
    path.write_text(text + "\n[stages.disturbance]\nmax_linear = 3.0\nmax_angular = 10.0\n")
    with pytest.raises(ConfigError, match="stages.disturbance.time_constant"):
        read_pair_file(path)


def test_a_rider_with_the_stage_estimates_while_it_balances(monkeypatch) -> None:
    """The stage wired into the MPC rider (the CyberDog2 standing on the skateboard, 0.3 s,
    the MPC from the first tick, not after the pair's PD start): its vertical row is read at
    each MPC tick after the first, stays finite and within its bound, and the rider stands."""
    monkeypatch.setattr("ridempc.mpc.rider_parts.start_readiness", lambda *args: None)
    from ridempc.boards import load_board
    from ridempc.mpc.rider import MpcRider
    from ridempc.mpc.stages.drifts import disturbance_observer
    from ridempc.pair_description import DisturbanceStage
    from ridempc.robots import load_robot
    from ridempc.scenarios import resolve_scenario
    from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
    from ridempc.sim.scene import build_scene
    from ridempc.sim.simulation import Simulation

    dog = load_robot("cyberdog2")
    rider = MpcRider(dog, "skateboard")
    stage = DisturbanceStage(
        time_constant=0.3, max_linear=3.0, max_angular=10.0, rows=("vertical",)
    )
    description = rider.pair.description
    stages = description.stages.model_copy(update={"disturbance": stage})
    rider.pair = rider.pair._replace(description=description.model_copy(update={"stages": stages}))
    rider.disturbance = disturbance_observer(rider.pair, rider.mpc.reference.state_names)
    rider.drifts = rider._drift_sources()  # the stage list built again with it
    assert rider.disturbance is not None
    assert rider.disturbance.rows == (rider.mpc.reference.state_names.index("vz"),)
    scenario = resolve_scenario("stand-still", "skateboard").with_duration(0.3)
    scene = build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
    result = Simulation(scene, rider, scenario).run()
    estimate = rider.disturbance.estimate
    assert np.all(np.isfinite(estimate)) and np.all(np.abs(estimate) <= 3.0)
    assert estimate[0] != 0.0
    assert not result.fell
