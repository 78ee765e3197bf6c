"""What one MPC solve returns: the planned states and inputs, and how the solve went."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["Plan", "shift_plan"]

Array = NDArray[np.float64]


class Plan(NamedTuple):
    """A plan over the horizon.

    Attributes:
        states: :math:`x_0 \\dots x_N`, (N + 1) x nx, the pair's state layout and units.
        inputs: :math:`u_0 \\dots u_{N-1}`, N x nu (forces [N] on the robot, world frame,
            joint velocities [rad/s], board inputs).
        first_input: :math:`u_0` (nu), what the controller applies until the next solve.
        status: OSQP's status string (``solved``, ``primal infeasible``, ...), or why the QP
            was not solved (``invalid data``, ``time limit exceeded``); ``..., accepted``
            for an unconverged solve within its residual bounds
            (:mod:`~ridempc.mpc.plan_acceptance`), ``..., elastic (slack s)`` for one
            solved in its elastic form (:mod:`~ridempc.mpc.elastic`).
        solve_time: Wall time of writing the new values into the QP and solving it [s].
        fallback: True when the QP gave no plan (neither OSQP nor its elastic form) and this
            is the previous plan shifted by one step (or, before any plan succeeded, the
            reference).
        iterations: ADMM iterations (0 when the solver was not run).
    """

    states: Array
    inputs: Array
    first_input: Array
    status: str
    solve_time: float
    fallback: bool
    iterations: int = 0

    def first_step_state(self, share: float) -> Array:
        """The planned state ``share`` [-] of the way through the first step (clipped to
        [0, 1]), linear between :math:`x_0` and :math:`x_1`: what the 500 Hz ticks follow
        between solves."""
        s = min(max(share, 0.0), 1.0)
        return np.asarray((1.0 - s) * self.states[0] + s * self.states[1])


def shift_plan(plan: Plan, status: str, solve_time: float, iterations: int = 0) -> Plan:
    """``plan`` one step later, its last state and input held: the fallback of a failed solve.

    Args:
        plan: The previous plan.
        status: Why the new solve failed.
        solve_time: Time the failed solve took [s].
        iterations: Iterations of the failed solve.
    """
    states = np.vstack([plan.states[1:], plan.states[-1:]])
    inputs = np.vstack([plan.inputs[1:], plan.inputs[-1:]])
    return Plan(states, inputs, inputs[0].copy(), status, solve_time, True, iterations)
