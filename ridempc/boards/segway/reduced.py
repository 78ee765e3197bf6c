"""The Segway's reduced model: closed-loop pitch, speed, yaw rate and unicycle kinematics.

The model is of the same kind as the Hovershoe's closed-loop model (hovershoe paper,
eqs. 4-8): the firmware's feedback appears as stiffness and damping of the platform pitch,
the forward acceleration follows the pitch, and the board moves as a unicycle. Two terms
are added for the firmware's wheel-speed feedback (the platform tilts back as it speeds
up), and the yaw rate, which on the Segway is commanded by the knee bar through the
firmware's yaw-rate loop rather than by a rider torque, follows the knee-bar angle with a
first-order lag. The drive force of eq. 8 is the firmware's balance law, so besides the
pitch it carries the pitch rate (the firmware's damping) and the speed, and the rider's
lean pushes the wheels back by reaction (:math:`c_7`); fitted without :math:`c_6, c_7` the
held-out speed error is about ten times larger (see the board's README):

.. math::

    J_\\theta \\ddot\\theta = -c_1 \\theta - c_2 \\dot\\theta - c_3 v + u_\\theta
    \\qquad (4')

    m \\dot v = c_4 \\theta + c_5 v + c_6 \\dot\\theta - c_7 u_\\theta \\qquad (8')

    \\tau_\\psi \\ddot\\psi = k_{turn} \\delta - \\dot\\psi \\qquad (5')

    \\dot x = v \\cos\\psi, \\quad \\dot y = v \\sin\\psi \\qquad (6, 7)

State :math:`s = (x, y, \\psi, \\theta, \\dot\\theta, v, \\dot\\psi)`: position of the axle's
middle [m], heading [rad], platform pitch (positive nose down) [rad], its rate [rad/s],
forward speed [m/s], yaw rate (positive to the left) [rad/s]. Input
:math:`(u_\\theta, \\delta)`: the rider's pitch torque on the platform (positive leaning
forward) [N m] and the knee-bar angle (positive pushed to the left) [rad]. With
:math:`c_3 = c_5 = c_6 = c_7 = 0` it is the hovershoe paper's model.

The dynamics use only arithmetic and ``xp.sin`` / ``xp.cos``, so ``xp`` may be NumPy or
CasADi (``import casadi as xp``).
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.segway.parameters import SegwayReducedParameters

__all__ = ["STATE", "STATE_QUANTITIES", "INPUT", "segway_dynamics", "simulate_segway"]

STATE: tuple[str, ...] = ("x", "y", "psi", "theta", "theta_rate", "speed", "yaw_rate")
# What each state is, by its canonical name (ridempc.boards.canonical): the same quantities
# every board's reduced model names.
STATE_QUANTITIES: dict[str, str] = {
    "x": "x",
    "y": "y",
    "psi": "heading",
    "theta": "pitch",
    "theta_rate": "pitch_rate",
    "speed": "speed",
    "yaw_rate": "yaw_rate",
}
INPUT: tuple[str, ...] = ("u_theta", "knee_bar")


def segway_dynamics(
    state: Any,
    control: Any,
    params: SegwayReducedParameters,
    xp: ModuleType = np,
) -> tuple[Any, ...]:
    """Time derivative of the reduced state (eqs. 4', 5', 6, 7, 8').

    Args:
        state: :math:`(x, y, \\psi, \\theta, \\dot\\theta, v, \\dot\\psi)` [m, m, rad, rad,
            rad/s, m/s, rad/s].
        control: :math:`(u_\\theta, \\delta)` [N m, rad].
        params: The identified parameters.
        xp: Math module (``numpy`` or ``casadi``).

    Returns:
        The seven derivatives, in state order.
    """
    _, _, psi, theta, theta_rate, speed, yaw_rate = (state[i] for i in range(7))
    u_theta, knee = control[0], control[1]
    p = params
    theta_acc = (-p.c1 * theta - p.c2 * theta_rate - p.c3 * speed + u_theta) / p.pitch_inertia
    speed_acc = (p.c4 * theta + p.c5 * speed + p.c6 * theta_rate - p.c7 * u_theta) / p.mass
    yaw_acc = (p.k_turn * knee - yaw_rate) / p.tau_turn
    return (
        speed * xp.cos(psi),
        speed * xp.sin(psi),
        yaw_rate,
        theta_rate,
        theta_acc,
        speed_acc,
        yaw_acc,
    )


def simulate_segway(
    params: SegwayReducedParameters,
    initial: NDArray[np.float64],
    controls: NDArray[np.float64],
    dt: float,
    substeps: int = 4,
) -> NDArray[np.float64]:
    """Integrate the reduced model (RK4, inputs held over each sample).

    Args:
        params: The identified parameters.
        initial: Initial state (7,).
        controls: Inputs at each sample, (n, 2) [N m, rad].
        dt: Sample period [s].
        substeps: RK4 steps per sample.

    Returns:
        States at each sample, (n, 7); row 0 is ``initial``.
    """
    n = len(controls)
    states = np.empty((n, len(STATE)))
    s = np.asarray(initial, dtype=float)
    h = dt / substeps

    def f(x: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.array(segway_dynamics(x, u, params))

    for k in range(n):
        states[k] = s
        u = controls[k]
        for _ in range(substeps):
            k1 = f(s, u)
            k2 = f(s + 0.5 * h * k1, u)
            k3 = f(s + 0.5 * h * k2, u)
            k4 = f(s + h * k3, u)
            s = s + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return states
