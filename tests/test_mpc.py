"""The 30 Hz linear MPC (ridempc.mpc): linearisation against finite differences, the QP built
once with a fixed pattern, closed loops on the reduced models of the skateboard and the
Hovershoes, the fallback of a failed solve, and the library reference's checks."""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.library.store import library_folder
from ridempc.mpc import (
    MPC_STEP,
    LinearMpc,
    MpcProblem,
    MpcSettings,
    build_linear_model,
    linearize,
    load_mpc_pair,
    select_reference,
    zero_order_hold,
)
from ridempc.mpc.friction import ROWS_PER_CONTACT
from ridempc.mpc.manoeuvre import RETARGET_BAND, Manoeuvre, ManoeuvreSelector, StateLayout
from ridempc.mpc.plan_acceptance import Acceptance
from ridempc.scenarios.scenario import Command
from ridempc.trajopt.schedule import Contact

PAIRS = [
    ("cyberdog2", "skateboard", "accelerate", 0.3),
    ("cassie", "hovershoes", "accelerate", 0.5),
]


@pytest.fixture(scope="module")
def skate_mpc() -> LinearMpc:
    return LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)


def _finite_difference(function, point: np.ndarray, step: float = 1e-6) -> np.ndarray:
    columns = []
    for j in range(len(point)):
        delta = np.zeros_like(point)
        delta[j] = step
        columns.append((function(point + delta) - function(point - delta)) / (2 * step))
    return np.column_stack(columns)


@pytest.mark.parametrize("robot, board, kind, target", PAIRS)
def test_linearisation_matches_finite_differences(
    robot: str, board: str, kind: str, target: float
) -> None:
    mpc = LinearMpc.from_library(robot, board, kind, target)
    rates, reference = mpc.model.rates, mpc.reference
    rng = np.random.default_rng(7)
    for _ in range(3):
        k = int(rng.integers(len(reference.inputs)))
        x0 = reference.states[k] + rng.normal(scale=0.02, size=reference.states.shape[1])
        u = reference.inputs[k] + rng.normal(scale=1.0, size=reference.inputs.shape[1])
        p = reference.parameters[k]

        def f(x: np.ndarray, u: np.ndarray = u, p: np.ndarray = p) -> np.ndarray:
            return np.asarray(rates(x, u, p)).ravel()

        _, jac_x, jac_u = (np.asarray(m) for m in mpc.model.jacobians(x0, u, p))
        np.testing.assert_allclose(jac_x, _finite_difference(f, x0), rtol=1e-5, atol=1e-5)
        by_input = _finite_difference(lambda v, x0=x0: f(x0, v), u)
        np.testing.assert_allclose(jac_u, by_input, rtol=1e-5, atol=1e-6)
        # Discrete: zero-order hold of the affine model, against SciPy's expm of the
        # augmented matrix (eq. 18).
        dt = MPC_STEP
        a_d, b_d, c_d = linearize(mpc.model, x0, u[None, :], p[None, :], dt)
        nx, nu = jac_u.shape
        augmented = np.zeros((nx + nu + 1, nx + nu + 1))
        augmented[:nx, :nx], augmented[:nx, nx : nx + nu] = jac_x * dt, jac_u * dt
        augmented[:nx, -1] = f(x0) * dt
        exact = expm(augmented)
        np.testing.assert_allclose(a_d[0], exact[:nx, :nx], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(b_d[0], exact[:nx, nx : nx + nu], rtol=1e-9, atol=1e-9)
        # At the operating point the step is the linear model's: x0 + g.
        np.testing.assert_allclose(
            a_d[0] @ x0 + b_d[0] @ u + c_d[0], x0 + exact[:nx, -1], rtol=1e-9, atol=1e-9
        )
    # The paper's eq. (17): the state Jacobian of the drift alone.
    held = build_linear_model(rates, hold_lever_arms=True)
    _, jac_held, _ = (np.asarray(m) for m in held.jacobians(x0, u, p))
    drift = _finite_difference(lambda x: np.asarray(rates(x, 0 * u, p)).ravel(), x0)
    np.testing.assert_allclose(jac_held, drift, rtol=1e-5, atol=1e-5)
    assert held.state_pattern.sum() < mpc.model.state_pattern.sum()


def test_zero_order_hold_of_badly_scaled_stiff_stacks_matches_expm() -> None:
    """Balancing and the Paterson-Stockmeyer series change how, not what, is computed: a
    stack of distinct matrices with units spread over six decades and a -140 rad/s mode
    (the Segway's platform), and a stack repeating one matrix, against SciPy's expm of
    the augmented matrix."""
    rng = np.random.default_rng(3)
    nx, dt = 8, MPC_STEP
    units = np.diag(10.0 ** rng.uniform(-3.0, 3.0, nx))
    base = np.diag([-140.0, -3.0, 0.0, 0.0, 1.5, -0.2, 0.0, -20.0])
    base[np.triu_indices(nx, 1)] = rng.normal(scale=4.0, size=nx * (nx - 1) // 2)
    distinct = np.stack(
        [units @ (base + rng.normal(scale=0.5, size=(nx, nx))) @ np.linalg.inv(units)
         for _ in range(4)]
    )  # fmt: skip
    for stack in (distinct, np.repeat(distinct[:1], 3, axis=0)):
        exponential, phi = zero_order_hold(stack, dt)
        for k, a_c in enumerate(stack):
            augmented = np.zeros((2 * nx, 2 * nx))
            augmented[:nx, :nx], augmented[:nx, nx:] = a_c * dt, np.eye(nx) * dt
            exact = expm(augmented)
            scale_e, scale_phi = np.abs(exact[:nx, :nx]).max(), np.abs(exact[:nx, nx:]).max()
            np.testing.assert_allclose(exponential[k], exact[:nx, :nx], atol=1e-12 * scale_e)
            np.testing.assert_allclose(phi[k], exact[:nx, nx:], atol=1e-12 * scale_phi)


def _pyramid_violation(problem: MpcProblem, inputs: np.ndarray) -> float:
    rows = np.einsum("kij,kj->ki", problem.constraint_matrix, inputs)
    return float(
        max((rows - problem.constraint_upper).max(), (problem.constraint_lower - rows).max())
    )


def test_qp_is_built_once_and_updates_only_values(
    skate_mpc: LinearMpc, monkeypatch: pytest.MonkeyPatch
) -> None:
    reference = skate_mpc.reference
    first = skate_mpc.problem(0.0, reference.states[0])
    push = next(i for i, contacts in enumerate(reference.schedule) if Contact.GROUND in contacts)
    t_push = reference.times[push] - 0.1  # the horizon spans swing, push and their change
    second = skate_mpc.problem(t_push, reference.sample(t_push, 1, MPC_STEP).states[0])
    assert first.constraint_upper.tolist() != second.constraint_upper.tolist()

    qp = skate_mpc.build_qp(first, eps_abs=1e-6, eps_rel=1e-6, time_limit=1.0)
    indices, indptr = qp.pattern
    nnz = qp.nnz
    _, a_first = qp.matrices(first)
    _, a_second = qp.matrices(second)
    for matrix in (a_first, a_second):
        assert matrix.nnz == nnz
        np.testing.assert_array_equal(matrix.indices, indices)
        np.testing.assert_array_equal(matrix.indptr, indptr)
    assert not np.allclose(a_first.data, a_second.data)

    def no_second_setup(*args: object, **kwargs: object) -> None:
        raise AssertionError("the QP was set up again")

    monkeypatch.setattr(qp._solver, "setup", no_second_setup)
    for problem in (first, second):
        plan = qp.solve(problem)
        assert plan.status == "solved" and not plan.fallback
        x, u = plan.states, plan.inputs
        np.testing.assert_allclose(x[0], problem.initial_state, atol=1e-6)
        residual = x[1:] - np.einsum("kij,kj->ki", problem.A, x[:-1])
        residual -= np.einsum("kij,kj->ki", problem.B, u) + problem.c
        assert np.abs(residual).max() < 1e-4
        assert _pyramid_violation(problem, u) < 1e-4
        assert np.all(u >= problem.input_lower - 1e-4) and np.all(u <= problem.input_upper + 1e-4)
    assert qp.nnz == nnz and qp.failures == 0
    # The second horizon holds a swinging foot: its force is zero, and the pushing foot on
    # the ground has a force.
    window = reference.sample(t_push, qp.horizon, MPC_STEP)
    pusher = window.contacts[-1].index(Contact.GROUND)
    swinging = [k for k, c in enumerate(window.contacts) if c[pusher] is Contact.SWING]
    assert swinging and len(swinging) < qp.horizon
    forces = plan.inputs[:, reference.force_index[pusher]]
    assert np.abs(forces[swinging]).max() < 1e-4
    assert forces[-1, 2] > 1.0


def _closed_loop(mpc: LinearMpc, x0: np.ndarray, substeps: int = 10) -> dict[str, np.ndarray]:
    """The MPC's first input held for one step on ``rates`` (RK4), over the reference."""
    rates, reference, dt = mpc.model.rates, mpc.reference, mpc.settings.dt
    steps = round(reference.duration / dt)
    h = dt / substeps
    x = x0.copy()
    states, times = [], []
    for i in range(steps):
        t = i * dt
        plan = mpc.update(t, x)
        u, p = plan.first_input, reference.sample(t, 1, dt).parameters[0]

        def f(y: np.ndarray, u: np.ndarray = u, p: np.ndarray = p) -> np.ndarray:
            return np.asarray(rates(y, u, p)).ravel()

        for _ in range(substeps):
            k1 = f(x)
            k2 = f(x + h / 2 * k1)
            k3 = f(x + h / 2 * k2)
            k4 = f(x + h * k3)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(x.copy())
        times.append(t + dt)
    assert mpc.qp is not None
    solve_times = np.array([r.solve_time for r in mpc.qp.history])
    print(
        f"\n{reference.name}: {steps} solves, median {np.median(solve_times) * 1e3:.2f} ms, "
        f"p99 {np.percentile(solve_times, 99) * 1e3:.2f} ms, failures {mpc.qp.failures}"
    )
    track = reference.sample(0.0, steps, dt).states[1:]
    return {"states": np.array(states), "reference": track, "times": np.array(times)}


def _errors(run: dict[str, np.ndarray], names: tuple[str, ...]) -> dict[str, float]:
    gap = np.abs(run["states"] - run["reference"]).max(axis=0)
    errors = dict(zip(names, gap.tolist(), strict=True))
    print("largest tracking errors: " + ", ".join(f"{n} {e:.3g}" for n, e in errors.items()))
    return errors


def _perturbed(mpc: LinearMpc, offsets: dict[str, float]) -> np.ndarray:
    names = mpc.reference.state_names
    x0 = mpc.reference.states[0].copy()
    for name, offset in offsets.items():
        x0[names.index(name)] += offset
    return x0


def test_closed_loop_skateboard_push() -> None:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)
    offsets = {"com_y": 0.01, "com_z": -0.005, "trunk_roll": 0.02, "trunk_pitch": -0.02}
    run = _closed_loop(mpc, _perturbed(mpc, {**offsets, "board_roll": 0.01}))
    names = mpc.reference.state_names
    errors = _errors(run, names)
    speed = run["states"][-1, names.index("board_v")]
    assert abs(speed - 0.3) < 0.03, speed
    assert mpc.qp is not None and mpc.qp.failures == 0
    bounds = {
        "com_x": 0.03,
        "com_y": 0.03,
        "com_z": 0.01,
        "trunk_roll": 0.03,
        "trunk_pitch": 0.03,
        "trunk_yaw": 0.02,
        "vx": 0.03,
        "vy": 0.1,
        "board_v": 0.03,
        "board_roll": 0.05,
        "board_yaw": 0.02,
    }
    for name, bound in bounds.items():
        assert errors[name] < bound, (name, errors[name])
    joints = [errors[n] for n in names if n.startswith("q_")]
    assert max(joints) < 0.02


def test_closed_loop_hovershoes_lean() -> None:
    mpc = LinearMpc.from_library("cassie", "hovershoes", "accelerate", 0.5)
    offsets = {"com_x": 0.01, "com_y": 0.01, "pelvis_roll": 0.02, "pelvis_pitch": -0.02}
    run = _closed_loop(mpc, _perturbed(mpc, offsets))
    names = mpc.reference.state_names
    errors = _errors(run, names)
    for shoe in ("left_v", "right_v"):
        speed = run["states"][-1, names.index(shoe)]
        assert abs(speed - 0.5) < 0.05, (shoe, speed)
    assert mpc.qp is not None and mpc.qp.failures == 0
    bounds = {
        "com_x": 0.08,
        "com_y": 0.03,
        "com_z": 0.02,
        "pelvis_roll": 0.03,
        "pelvis_pitch": 0.03,
        "pelvis_yaw": 0.02,
        "vx": 0.05,
        "left_v": 0.1,
        "right_v": 0.1,
        "left_theta": 0.05,
        "right_theta": 0.05,
    }
    for name, bound in bounds.items():
        assert errors[name] < bound, (name, errors[name])


def test_infeasible_update_falls_back_to_the_shifted_plan(skate_mpc: LinearMpc) -> None:
    reference = skate_mpc.reference
    good = skate_mpc.problem(0.0, reference.states[0])
    qp = skate_mpc.build_qp(good)
    qp.rescue = None  # the fallback itself (the elastic rescue: tests/test_plan_acceptance.py)
    previous = qp.solve(good)
    assert not previous.fallback and qp.failures == 0
    # Contradictory: a standing foot must push down harder than its pyramid allows.
    lower = good.input_lower.copy()
    lower[:, reference.force_index[0][2]] = (
        10.0 * load_mpc_pair("cyberdog2", "skateboard").max_force
    )
    bad = dataclasses.replace(good, input_lower=lower)
    plan = qp.solve(bad)
    assert plan.fallback and plan.status != "solved"
    assert qp.failures == 1
    np.testing.assert_allclose(plan.states[:-1], previous.states[1:])
    np.testing.assert_allclose(plan.first_input, previous.inputs[1])
    assert qp.history[-1].fallback and qp.history[-1].status == plan.status
    # Failing again shifts again; a good problem recovers.
    again = qp.solve(bad)
    np.testing.assert_allclose(again.first_input, previous.inputs[2])
    assert qp.failures == 2
    assert not qp.solve(good).fallback


def test_the_solve_budget_is_iterations_not_wall_time(skate_mpc: LinearMpc) -> None:
    """Without a time limit a solve cut at ``max_iter`` (neither continued nor rescued)
    falls back, whatever the load."""
    good = skate_mpc.problem(0.0, skate_mpc.reference.states[0])
    qp = skate_mpc.build_qp(good, max_iter=3)
    qp.acceptance, qp.rescue = Acceptance(extra_iterations=0), None
    assert qp.time_limit is None
    plan = qp.solve(good)
    assert plan.fallback and plan.iterations == 3 and qp.failures == 1
    roomy = skate_mpc.build_qp(good)
    assert not roomy.solve(good).fallback


def test_problem_is_checked(skate_mpc: LinearMpc) -> None:
    good = skate_mpc.problem(0.0, skate_mpc.reference.states[0])
    with pytest.raises(ValueError, match="B has shape"):
        dataclasses.replace(good, B=good.B[:, :-1, :])
    with pytest.raises(ValueError, match="above"):
        dataclasses.replace(good, input_lower=good.input_upper + 1.0)
    with pytest.raises(ValueError, match="NaN"):
        dataclasses.replace(good, initial_state=np.full(good.nx, np.nan))
    with pytest.raises(ValueError, match="non-negative"):
        dataclasses.replace(good, state_weights=-good.state_weights)


def test_reference_schedule_and_steady_riding(skate_mpc: LinearMpc) -> None:
    reference = skate_mpc.reference
    assert reference.contact_names == ("FL_contact", "FR_contact", "RL_contact", "RR_contact")
    assert reference.force_index.tolist()[2] == [6, 7, 8]
    kinds = {c for contacts in reference.schedule for c in contacts}
    assert kinds == {Contact.BOARD, Contact.GROUND, Contact.SWING}
    # Parameters (the deck flags) agree with the schedule.
    on_deck = np.array([[c is Contact.BOARD for c in cs] for cs in reference.schedule])
    np.testing.assert_array_equal(on_deck, reference.parameters > 0.5)
    # After the end: the board rolls on at its final speed, the rest is held once the dog
    # has settled over its feet (test_settle).
    assert reference.settle_inputs is not None
    window = reference.sample(reference.duration + reference.settle_time + 1.0, 3, MPC_STEP)
    names = reference.state_names
    x = window.states[:, names.index("board_x")]
    speed = reference.states[-1, names.index("board_v")]
    np.testing.assert_allclose(np.diff(x), speed * MPC_STEP, rtol=0.05)
    np.testing.assert_allclose(
        window.states[:, names.index("com_z")], reference.states[-1, 2], atol=1e-3
    )
    settled = reference.inputs[-1] + reference.settle_inputs
    np.testing.assert_allclose(window.inputs, np.tile(settled, (3, 1)))
    # The 500 Hz tick's states alone are the window's, before, during and after the entry.
    for t in (-1.0, 0.4 * reference.duration, reference.duration + 1.0):
        times = t + MPC_STEP * np.arange(4)
        np.testing.assert_array_equal(
            reference.states_at(times), reference.sample(t, 3, MPC_STEP).states
        )


def test_reference_blends_neighbouring_entries() -> None:
    reference = select_reference("cassie", "hovershoes", "accelerate", 0.75)
    low = select_reference("cassie", "hovershoes", "accelerate", 0.5)
    high = select_reference("cassie", "hovershoes", "accelerate", 1.0)
    assert "+" in reference.name and reference.target == pytest.approx(0.75)
    assert low.duration < reference.duration < high.duration
    names = reference.state_names
    assert reference.states[-1, names.index("left_v")] == pytest.approx(0.75, abs=1e-6)
    assert [p.mode for p in reference.phases] == [p.mode for p in low.phases]
    # The skateboard's entries differ in their pushes: the nearest is taken.
    nearest = select_reference("cyberdog2", "skateboard", "accelerate", 0.45)
    assert nearest.name == "accelerate-0.50"
    beyond = select_reference("cyberdog2", "skateboard", "accelerate", 5.0)
    assert beyond.name == "accelerate-1.00"


def test_bad_library_raises_config_error(tmp_path: Path) -> None:
    folder = tmp_path / "cyberdog2-skateboard"
    shutil.copytree(library_folder("cyberdog2", "skateboard"), folder)
    with pytest.raises(ConfigError, match="no 'stop' entries"):
        select_reference("cyberdog2", "skateboard", "stop", 0.3, folder=folder)
    entry = folder / "accelerate-0.30.npz"
    entry.write_bytes(entry.read_bytes()[:100])
    with pytest.raises(ConfigError, match="accelerate-0.30.npz"):
        select_reference("cyberdog2", "skateboard", "accelerate", 0.3, folder=folder)
    entry.unlink()
    with pytest.raises(ConfigError, match="accelerate-0.30.npz"):
        select_reference("cyberdog2", "skateboard", "accelerate", 0.3, folder=folder)
    manifest = folder / "manifest.json"
    raw = json.loads(manifest.read_text())
    raw["entries"] = [e for e in raw["entries"] if e["name"] == "accelerate-0.50"]
    raw["entries"][0]["metadata"]["phases"][0]["contacts"] = ["board", "flying"]
    manifest.write_text(json.dumps(raw))
    with pytest.raises(ConfigError, match="accelerate-0.50.npz: metadata phase 0"):
        select_reference("cyberdog2", "skateboard", "accelerate", 0.5, folder=folder)
    manifest.unlink()
    with pytest.raises(ConfigError, match="manifest.json"):
        select_reference("cyberdog2", "skateboard", "accelerate", 0.3, folder=folder)
    with pytest.raises(UnknownNameError):
        load_mpc_pair("cassie", "skateboard")


def test_retarget_keeps_the_qp() -> None:
    mpc = LinearMpc.from_library("cassie", "segway", "accelerate", 0.5)
    x0 = mpc.reference.states[0]
    assert not mpc.update(0.0, x0).fallback
    qp = mpc.qp
    mpc.retarget("stop", 1.0)
    assert mpc.reference.name == "stop-1.00"
    plan = mpc.update(0.0, mpc.reference.states[0])
    assert mpc.qp is qp and not plan.fallback


def test_settings_are_checked() -> None:
    with pytest.raises(ConfigError, match="horizon"):
        MpcSettings(horizon=0)
    assert MpcSettings().dt == pytest.approx(1.0 / 30.0)
    assert ROWS_PER_CONTACT == 5
    with pytest.raises(ConfigError, match="terminal factor"):
        MpcSettings(terminal_factor=-1.0)


def test_the_terminal_weight_is_the_pairs_unless_the_settings_set_it() -> None:
    """:math:`Q_N` is the pair's terminal factor times :math:`Q` (30 on the Hovershoes, 10
    on the Segway), or the settings' where they give one."""
    for board, factor in (("hovershoes", 30.0), ("segway", 10.0)):
        mpc = LinearMpc.from_library("cassie", board, "accelerate", 0.5)
        assert mpc.terminal_factor == mpc.pair.terminal_factor == pytest.approx(factor)
        problem = mpc.problem(0.0, mpc.reference.states[0])
        np.testing.assert_allclose(problem.final_weights, factor * problem.state_weights)
    settings = MpcSettings(terminal_factor=2.0)
    mpc = LinearMpc.from_library("cassie", "hovershoes", "accelerate", 0.5, settings=settings)
    problem = mpc.problem(0.0, mpc.reference.states[0])
    np.testing.assert_allclose(problem.final_weights, 2.0 * problem.state_weights)


def test_fixed_inputs_are_held_over_the_horizon() -> None:
    """The Segway's knee bar pinned at zero: every plan step keeps it there, and an unknown
    name is refused."""
    settings = MpcSettings(fixed_inputs={"knee_bar": 0.0})
    mpc = LinearMpc.from_library("cassie", "segway", "turn", 0.5, settings=settings)
    bar = list(mpc.reference.input_names).index("knee_bar")
    assert np.max(np.abs(mpc.reference.inputs[:, bar])) > 0.01  # the library turns with it
    plan = mpc.update(1.0, mpc.reference.states[30])
    assert np.max(np.abs(plan.inputs[:, bar])) < 1e-6
    with pytest.raises(ConfigError, match="fixed input 'steering'"):
        LinearMpc.from_library(
            "cassie", "segway", "turn", 0.5, settings=MpcSettings(fixed_inputs={"steering": 0.0})
        )


def test_a_ramped_command_retargets_in_steps_not_at_every_tick() -> None:
    selector = ManoeuvreSelector("cassie", "segway")
    current = selector.initial()
    assert selector.select(Command(velocity=0.01), current, 0.0, 0.0) is current  # rest: hold
    targets = []
    for t in np.arange(0.0, 1.0 + 1e-9, 1.0 / 30.0):  # 0 -> 1 m/s over 1 s
        wanted = selector.select(Command(velocity=float(t)), current, float(t), 0.0)
        if wanted is not current:
            targets.append(wanted.target)
            current = wanted
    assert len(targets) <= 1.0 / RETARGET_BAND + 1  # not 30 restarts
    settled = selector.select(Command(velocity=1.0), current, 1.05, 0.0)  # the ramp has ended
    current = settled if settled is not current else current
    assert current.kind == "accelerate" and current.target == pytest.approx(1.0)
    assert all(b - a >= RETARGET_BAND - 1e-9 for a, b in zip(targets, targets[1:], strict=False))
    # a step beyond the band restarts at once; one inside it keeps the running manoeuvre
    stepped = selector.select(Command(velocity=2.0), current, 2.0, 1.0)
    assert stepped.target == pytest.approx(2.0)
    assert selector.select(Command(velocity=2.1), stepped, 2.1, 1.0) is stepped


def test_a_slower_speed_is_ridden_at_not_started_from_rest() -> None:
    """Slowing from 4 to 3.75 m/s picks the 3.75 m/s entry where it rides steadily, not
    its start at rest; speeding up still starts where the reference passes the speed, and
    from rest where it first reaches the pair's start speed."""
    times = np.linspace(0.0, 8.0, 81)
    speeds = np.clip((times - 0.5) / 7.0, 0.0, 1.0) * 3.75  # rest -> 3.75 m/s
    slower = ManoeuvreSelector.phase_start(times, speeds, 3.97, 10.0, "accelerate")
    assert 10.0 - slower == pytest.approx(times[-1])
    faster = ManoeuvreSelector.phase_start(times, speeds, 1.5, 10.0, "accelerate")
    match = int(np.argmin(np.abs(times - (10.0 - faster))))
    assert speeds[match - 1] < 1.5 <= speeds[match]  # the first node at that speed
    # from rest, the steady start and the slowest of the lean-in are skipped
    assert 10.0 - ManoeuvreSelector.phase_start(times, speeds, 0.0, 10.0, "accelerate") == 0.0
    lean = ManoeuvreSelector.phase_start(times, speeds, 0.0, 10.0, "accelerate", least=0.03)
    match = int(np.argmin(np.abs(times - (10.0 - lean))))
    assert speeds[match - 1] < 0.03 <= speeds[match]
    stop = speeds[::-1]  # 3.75 m/s -> rest: a stop is matched on the speed alone
    braking = ManoeuvreSelector.phase_start(times, stop, 1.0, 10.0, "stop", least=3.0)
    assert braking == ManoeuvreSelector.phase_start(times, stop, 1.0, 10.0, "stop")


def test_slowing_down_brakes_along_a_stop_then_rides_at_the_command() -> None:
    selector = ManoeuvreSelector("cassie", "segway")
    riding = Manoeuvre("accelerate", 4.0, 0.0)
    command = Command(velocity=3.7)
    braking = selector.select(command, riding, 20.0, 4.0)
    assert braking.kind == "stop" and braking.target == pytest.approx(4.0)
    assert selector.select(command, braking, 21.0, 3.96) is braking  # still braking
    settled = selector.select(command, braking, 22.0, 3.7)
    assert settled.kind == "accelerate" and settled.target == pytest.approx(3.7)


def test_a_commanded_roll_moves_the_reference_to_a_balance(skate_mpc: LinearMpc) -> None:
    """Rolled by 0.05 rad with the static shift, the reference's force-driven accelerations
    are what they were unrolled (to first order); rolled alone they are not."""
    layout = StateLayout.from_pair(
        skate_mpc.reference.state_names, load_mpc_pair("cyberdog2", "skateboard")
    )
    names, roll = layout.names, layout.names["board_roll"]
    t = 6.0
    shift = skate_mpc.static_shift(t, roll, layout.rider_states)
    window = skate_mpc.reference.sample(t, 1, skate_mpc.settings.dt)
    x, u, p = window.states[0], window.inputs, window.parameters

    def rates(state: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        return skate_mpc.model.evaluate(state, inputs, p)[0][0]

    base = rates(x, u)
    delta = np.zeros_like(x)
    delta[roll] = 0.05
    alone = rates(x + delta, u) - base
    balanced = rates(x + delta + 0.05 * shift.states, u + 0.05 * shift.inputs) - base
    dynamic = [names[n] for n in ("vx", "vy", "vz", "wx", "wy", "wz", "board_roll_rate")]
    assert np.abs(alone[dynamic]).max() > 10.0  # [rad/s^2] the trucks' spring, unheld
    assert np.abs(balanced[dynamic]).max() < 0.05 * np.abs(alone[dynamic]).max()
    # the rider leans to the low side; the board's own states stay
    assert shift.states[names["com_y"]] < -0.1
    assert not shift.states[[names[n] for n in names if n.startswith(layout.prefixes)]].any()
    # rolling at 1 rad/s, the rider sways at the lean's rate
    a_c = skate_mpc.model.evaluate(x, u, p)[1][0]
    np.testing.assert_allclose(
        (a_c @ shift.velocities)[names["com_y"]], shift.states[names["com_y"]], rtol=1e-6
    )


def test_a_commanded_turn_lays_an_arc_over_the_reference() -> None:
    """``with_turn``: no rate leaves the problem as it is; 0.5 rad/s turns every heading by
    0.5 k dt, adds the rate to the yaw rates, turns the centre of mass's velocity and path
    steps with it (speeds and step lengths kept), and turns rider and shoes as one body:
    the left shoe (the frame's anchor) stays at node 0, each shoe's offset from the centre
    of mass turns with the heading, and the outer shoe rolls faster by the rate times
    their spacing."""
    mpc = LinearMpc.from_library("cassie", "hovershoes", "accelerate", 1.0)
    layout = StateLayout.from_pair(mpc.reference.state_names, load_mpc_pair("cassie", "hovershoes"))
    n = layout.names
    problem = mpc.problem(5.0, mpc.reference.sample(5.0, 0, 1.0).states[0])
    steps = problem.state_reference.shape[0] - 1
    assert ManoeuvreSelector.with_turn(problem, layout, np.zeros(steps)) is problem
    turned = ManoeuvreSelector.with_turn(problem, layout, np.full(steps, 0.5), 0.1)
    before, after = problem.state_reference, turned.state_reference
    angle = 0.1 + 0.5 * problem.dt * np.arange(steps + 1)
    for name in ("left_psi", "right_psi", "pelvis_yaw"):
        np.testing.assert_allclose(after[:, n[name]] - before[:, n[name]], angle, atol=1e-12)
    for name in ("left_psi_dot", "right_psi_dot", "wz"):
        np.testing.assert_allclose(after[:, n[name]] - before[:, n[name]], 0.5, atol=1e-12)
    speed = np.hypot(after[:, n["vx"]], after[:, n["vy"]])
    np.testing.assert_allclose(speed, np.hypot(before[:, n["vx"]], before[:, n["vy"]]))
    heading = np.arctan2(after[:, n["vy"]], after[:, n["vx"]])
    np.testing.assert_allclose(heading, angle, atol=1e-6)  # riding straight along x before

    def xy(states: np.ndarray, prefix: str) -> np.ndarray:
        return states[:, [n[f"{prefix}x"], n[f"{prefix}y"]]]

    lengths = np.linalg.norm(np.diff(xy(after, "com_"), axis=0), axis=1)
    original = np.linalg.norm(np.diff(xy(before, "com_"), axis=0), axis=1)
    np.testing.assert_allclose(lengths, original, atol=1e-12)
    np.testing.assert_allclose(xy(after, "left_")[0], xy(before, "left_")[0], atol=1e-12)
    cos, sin = np.cos(angle), np.sin(angle)
    for prefix in ("left_", "right_"):
        offset = xy(before, prefix) - xy(before, "com_")
        turned_offset = np.column_stack(
            [cos * offset[:, 0] - sin * offset[:, 1], sin * offset[:, 0] + cos * offset[:, 1]]
        )
        np.testing.assert_allclose(xy(after, prefix) - xy(after, "com_"), turned_offset, atol=1e-12)
    spacing = before[:, n["left_y"]] - before[:, n["right_y"]]
    assert spacing.min() > 0.3  # [m] the shoes side by side
    np.testing.assert_allclose(
        after[:, n["right_v"]] - after[:, n["left_v"]],
        before[:, n["right_v"]] - before[:, n["left_v"]] + 0.5 * spacing,
        atol=1e-9,
    )


def test_a_coasting_rider_slows_the_steady_ride_to_the_board(skate_mpc: LinearMpc) -> None:
    """``coasting``: past the push-off's end the skateboard's steady ride is slowed to the
    board's speed: half the speed halves the rider's and the board's speeds and the steps
    of their positions from node 0, and leaves the rest (height, roll, joints); at rest
    it stands. Only the pairs without ``stop`` entries coast."""
    layout = StateLayout.from_pair(
        skate_mpc.reference.state_names, load_mpc_pair("cyberdog2", "skateboard")
    )
    n = layout.names
    end = float(skate_mpc.reference.times[-1])
    problem = skate_mpc.problem(end + 1.0, skate_mpc.reference.states[-1])
    before = problem.state_reference
    target = before[0, n["board_v"]]
    assert target == pytest.approx(0.3, abs=0.02)
    half = ManoeuvreSelector.coasting(problem, layout, 0.5 * target).state_reference
    for name in ("vx", "board_v"):
        np.testing.assert_allclose(half[:, n[name]], 0.5 * before[:, n[name]])
    for name in ("com_x", "board_x"):
        np.testing.assert_allclose(np.diff(half[:, n[name]]), 0.5 * np.diff(before[:, n[name]]))
        assert half[0, n[name]] == before[0, n[name]]
    others = [
        i
        for name, i in n.items()
        if name not in ("vx", "vy", "board_v") and not name.endswith(("_x", "_y"))
    ]
    np.testing.assert_array_equal(half[:, others], before[:, others])
    rest = ManoeuvreSelector.coasting(problem, layout, -0.01).state_reference
    assert not rest[:, [n["vx"], n["vy"], n["board_v"]]].any()
    np.testing.assert_allclose(rest[:, n["board_x"]], before[0, n["board_x"]])
    assert ManoeuvreSelector("cyberdog2", "skateboard").coasts
    assert not ManoeuvreSelector("cassie", "hovershoes").coasts


def test_swing_targets_follow_the_reference_feet_carried_by_the_board(
    skate_mpc: LinearMpc,
) -> None:
    """The reference's feet stand on the deck at rest and on the ground while pushing, and
    the targets move with the estimated board, not with the trunk."""
    from ridempc.estimation.state import BoardEstimate
    from ridempc.mpc.state_map import PlanarFrame
    from ridempc.mpc.swing import VELOCITY_STEP, ReferenceFeet
    from ridempc.robots import load_robot
    from ridempc.trajopt.skate_pair import skate_models
    from ridempc.wbc.model import WholeBodyModel

    reference = skate_mpc.reference
    layout = StateLayout.from_pair(reference.state_names, load_mpc_pair("cyberdog2", "skateboard"))
    model = WholeBodyModel(load_robot("cyberdog2"))
    feet = ReferenceFeet(model, reference.state_names, layout.base_prefix, layout.board_pose)
    assert feet.plans_feet
    robot, board = skate_models("cyberdog2", "skateboard")
    radius = float(np.mean(robot.foot_radius))
    on_deck = feet.points(reference.states[0])[:, 2]
    assert np.ptp(on_deck) < 2e-3 and on_deck[0] == pytest.approx(
        board.deck_height + radius, abs=5e-3
    )
    pusher = model.foot_names.index("RL_foot")
    pushing = [k for k, step in enumerate(reference.schedule) if step[pusher] is Contact.GROUND]
    middle = reference.times[pushing[len(pushing) // 2]]
    state = reference.sample(float(middle), 0, 1.0).states[0]
    assert feet.points(state)[pusher, 2] == pytest.approx(radius, abs=5e-3)
    # carried: a board 0.1 m ahead and 0.05 m left of the reference's carries every target
    x_b, y_b, psi_b = layout.board_pose(state)
    moved = BoardEstimate(
        feet=(),
        position=np.array([x_b + 0.1, y_b + 0.05, 0.1]),
        yaw=psi_b,
        pitch=0.0,
        roll=0.0,
        velocity=np.array([0.5, 0.0, 0.0]),
        yaw_rate=0.0,
    )
    frame = PlanarFrame()
    states = reference.sample(float(middle), 1, VELOCITY_STEP).states
    at_plan, _ = feet.targets(states, frame, None)
    carried, velocity = feet.targets(states, frame, moved)
    assert carried - at_plan == pytest.approx(np.tile([0.1, 0.05, 0.0], (4, 1)), abs=1e-9)
    assert np.all(np.isfinite(velocity))


def test_a_library_floor_on_deck_forces_is_the_mpcs_too(skate_mpc: LinearMpc) -> None:
    """The library's least deck force (options.min_board_force, per foot's weight share)
    bounds the MPC's normal forces on the deck, never on the ground or a swinging foot."""
    share = skate_mpc.reference.min_board_share
    assert share > 0.0
    problem = skate_mpc.problem(0.0, skate_mpc.reference.states[0])
    least = share * skate_mpc.pair.weight / len(skate_mpc.reference.force_index)
    normals = problem.constraint_lower[:, ::ROWS_PER_CONTACT]
    for step, contacts in zip(normals, problem.contacts, strict=True):
        for value, kind in zip(step, contacts, strict=True):
            assert value == pytest.approx(least if kind is Contact.BOARD else 0.0)
    # and every stance foot on the deck carries it in the library itself
    reference = skate_mpc.reference
    for k, contacts in enumerate(reference.schedule):
        for i, kind in enumerate(contacts):
            if kind is Contact.BOARD:
                assert reference.inputs[k, reference.force_index[i][2]] >= least - 1e-3
