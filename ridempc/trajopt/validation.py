"""Re-simulating stored trajectories with another integrator, to measure their drift.

The optimisation integrates with the Hermite-Simpson rule on its grid (:mod:`.problem`). Here
the same continuous dynamics :math:`\\dot x = f(x, u_k, p_k)`, input held over each interval,
are integrated by SciPy's adaptive Runge-Kutta 4(5) (``solve_ivp``, method ``RK45``, tight
tolerances), in three ways:

- **local**: each interval from its stored start state; the gap to the stored end state is
  the discretisation error of one interval (every state);
- **board**: the board's reduced model alone over the whole horizon, from its initial
  state, driven by the rider's stored trajectory (cubic Hermite interpolation between
  nodes, the collocation polynomial): does the board reach the stored speed, roll and
  heading when the rider does what the plan says?
- **open loop**: the whole model from the initial state. The rider's single rigid body has
  no feedback and its foot contacts are held by the optimisation's constraints, not by
  the dynamics, so the rollout departs from the plan; what is reported is how long it
  stays within ``OPEN_LOOP_TOLERANCE`` of it (every state, in its units).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import casadi as ca
import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

__all__ = ["OPEN_LOOP_TOLERANCE", "Drift", "resimulate"]

Array = NDArray[np.float64]
RTOL, ATOL = 1e-9, 1e-11
OPEN_LOOP_TOLERANCE = 0.01  # [m], [rad], [m/s], [rad/s]


@dataclass(frozen=True)
class Drift:
    """Gaps between a stored trajectory and its re-simulation (max-norms, state units).

    Attributes:
        local: Largest one-interval gap over every state.
        local_board: Largest one-interval gap over the board's states.
        board: Largest gap of the board's states over the horizon (board-only rollout).
        board_final: Gap of each board state at the end of the board-only rollout.
        open_loop_time: How long the open-loop rollout of the whole model stays within
            ``OPEN_LOOP_TOLERANCE`` of the stored trajectory [s].
        integrator: What integrated.
    """

    local: float
    local_board: float
    board: float
    board_final: dict[str, float]
    open_loop_time: float
    integrator: str = f"scipy solve_ivp RK45, rtol {RTOL:g}, atol {ATOL:g}"


def _hermite(x0: Array, x1: Array, f0: Array, f1: Array, h: float, s: float) -> Array:
    """Cubic Hermite interpolant at fraction ``s`` of an interval of length ``h``."""
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * x0 + h10 * h * f0 + h01 * x1 + h11 * h * f1


def resimulate(
    rates: ca.Function,
    times: Array,
    states: Array,
    inputs: Array,
    parameters: Array,
    board_states: Sequence[int],
    state_names: Sequence[str],
) -> Drift:
    """Re-simulate a stored trajectory with RK45 and measure the drift (see module doc).

    Args:
        rates: :math:`f(x, u, p)`.
        times: Node times [s] (N + 1).
        states: Stored states, (N + 1) x nx.
        inputs: Stored inputs, N x nu (held over each interval).
        parameters: Per-interval dynamics parameters, N x n_p.
        board_states: Indices of the board's states.
        state_names: Names of the states (for ``board_final``).
    """

    def f(x: Array, k: int) -> Array:
        return np.asarray(rates(x, inputs[k], parameters[k])).ravel()

    board = np.asarray(board_states, dtype=int)
    n = len(inputs)
    local = np.zeros(n)
    local_board = np.zeros(n)
    for k in range(n):
        sol = solve_ivp(
            lambda t, x, k=k: f(x, k), (times[k], times[k + 1]), states[k], rtol=RTOL, atol=ATOL
        )
        gap = np.abs(sol.y[:, -1] - states[k + 1])
        local[k] = gap.max()
        local_board[k] = gap[board].max()

    # Board alone, driven by the rider's interpolated trajectory.
    xb = states[0, board].copy()
    board_gap = 0.0
    for k in range(n):
        h = times[k + 1] - times[k]
        f0, f1 = f(states[k], k), f(states[k + 1], k)

        def board_rates(
            t: float, y: Array, k: int = k, h: float = h, f0: Array = f0, f1: Array = f1
        ) -> Array:
            x = _hermite(states[k], states[k + 1], f0, f1, h, (t - times[k]) / h)
            x[board] = y
            return f(x, k)[board]

        sol = solve_ivp(board_rates, (times[k], times[k + 1]), xb, rtol=RTOL, atol=ATOL)
        xb = sol.y[:, -1]
        board_gap = max(board_gap, float(np.abs(xb - states[k + 1, board]).max()))
    final = {state_names[i]: float(abs(xb[j] - states[-1, i])) for j, i in enumerate(board)}

    # Everything, open loop.
    x = states[0].copy()
    open_loop_time = float(times[-1] - times[0])
    for k in range(n):
        sol = solve_ivp(
            lambda t, y, k=k: f(y, k), (times[k], times[k + 1]), x, rtol=RTOL, atol=ATOL
        )
        x = sol.y[:, -1]
        if not np.abs(x - states[k + 1]).max() <= OPEN_LOOP_TOLERANCE:
            open_loop_time = float(times[k] - times[0])
            break
    return Drift(
        local=float(local.max()),
        local_board=float(local_board.max()),
        board=board_gap,
        board_final=final,
        open_loop_time=open_loop_time,
    )
