"""The deck's disturbance-torque estimate (ridempc.mpc.roll_observer): it finds a torque the
model misses on the deck's own roll dynamics, enters the MPC's discrete model as a held
rate, and rests outside four-leg balancing."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from ridempc.boards import load_board
from ridempc.boards.skateboard.reduced import simulate_roll
from ridempc.mpc import LinearMpc, linearize
from ridempc.mpc.plan import Plan
from ridempc.mpc.problem import MPC_STEP
from ridempc.mpc.roll_observer import RollObserver
from ridempc.trajopt.skateboard import skateboard_model

TICK = 0.03  # [s] the rider's MPC tick (15 ticks of 2 ms), a little under the 1/30 s step


@pytest.fixture(scope="module")
def deck():
    board = load_board("skateboard")
    assert board is not None
    return skateboard_model(board).reduced


def _plan(states: np.ndarray) -> Plan:
    return Plan(states, np.zeros((len(states) - 1, 1)), np.zeros(1), "solved", 0.0, False)


def _roll(deck, state: tuple[float, float], torque: float, duration: float) -> np.ndarray:
    """Eq. (6)-(7) from ``state`` under a held ``torque`` [N m], over ``duration`` [s]."""
    times = np.linspace(0.0, duration, 31)
    path = simulate_roll(
        times,
        np.full(31, torque),
        state,
        deck.roll_inertia,
        deck.roll_stiffness,
        deck.roll_damping,
    )
    return path[-1]


def test_it_finds_a_torque_the_model_misses(deck) -> None:
    """A deck loaded by 0.5 N m the model does not know settles at 0.5 / K_B rad; the
    plans, each predicting one step with the torque estimated so far, are wrong until the
    estimate reaches the hidden torque: on the free deck a tick's roll goes 0.18 of the way
    to its balance, so at a gain of 0.3 the estimate closes 5 % of its error a tick (time
    constant 0.55 s), within 2 % in 3 s (100 ticks)."""
    hidden = 0.5  # [N m]
    observer = RollObserver(0, 1, deck, gain=0.3)
    state = np.zeros(2)
    plan = None
    for _ in range(100):
        observer.update(state, plan, TICK / MPC_STEP)
        estimate = observer.torque
        plan = _plan(np.array([state, _roll(deck, tuple(state), estimate, MPC_STEP)]))
        state = _roll(deck, tuple(state), hidden, TICK)
    assert observer.torque == pytest.approx(hidden, rel=0.02)
    assert state[0] == pytest.approx(hidden / deck.roll_stiffness, rel=0.02)
    drift = observer.drift(4)
    assert drift[1] == pytest.approx(observer.torque / deck.roll_inertia)
    assert drift[[0, 2, 3]].tolist() == [0.0, 0.0, 0.0]


def test_it_starts_from_zero_after_a_reset(deck) -> None:
    """The first update after a reset only starts the estimate: the plan it is handed was
    solved without it (a push-off's)."""
    observer = RollObserver(0, 1, deck, gain=0.5)
    wrong = _plan(np.array([[0.1, 0.0], [0.1, 0.0]]))
    observer.update(np.zeros(2), wrong, 0.9)
    assert observer.torque == 0.0
    observer.update(np.zeros(2), wrong, 0.9)
    assert observer.torque == pytest.approx(-0.5 * deck.roll_stiffness * 0.1)
    observer.reset()
    observer.update(np.zeros(2), wrong, 0.9)
    assert observer.torque == 0.0
    with pytest.raises(ValueError, match="gain"):
        RollObserver(0, 1, deck, gain=0.0)


def test_a_drift_is_a_held_rate_in_the_discrete_model() -> None:
    """``linearize(..., drift)`` adds :math:`\\int_0^{\\Delta t} e^{A\\tau} d\\tau\\,\\Delta f`
    to each step's :math:`c_k` and leaves :math:`A_k, B_k` alone (exact zero-order hold)."""
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)
    window = mpc.reference.sample(0.5, 4, MPC_STEP)
    x0 = window.states[0]
    names = list(mpc.reference.state_names)
    drift = np.zeros(len(x0))
    drift[names.index("board_roll_rate")] = 4.0  # [rad/s^2]
    bare = linearize(mpc.model, x0, window.inputs, window.parameters)
    held = linearize(mpc.model, x0, window.inputs, window.parameters, drift=drift)
    np.testing.assert_array_equal(held.A, bare.A)
    np.testing.assert_array_equal(held.B, bare.B)
    _, a_c, _ = mpc.model.evaluate(x0, window.inputs, window.parameters)
    n = len(x0)
    for k in range(4):
        augmented = np.zeros((n + 1, n + 1))
        augmented[:n, :n], augmented[:n, n] = a_c[k], drift
        expected = expm(MPC_STEP * augmented)[:n, n]
        np.testing.assert_allclose(held.c[k] - bare.c[k], expected, atol=1e-9)
    # the deck rolls under it: half a^2 over a step, less what the bushings take back
    roll = names.index("board_roll")
    assert 0.0 < (held.c[0] - bare.c[0])[roll] < 0.5 * 4.0 * MPC_STEP**2
    problem = mpc.problem(0.5, x0, drift)
    np.testing.assert_allclose(problem.c[:4], held.c, rtol=1e-9, atol=1e-12)
