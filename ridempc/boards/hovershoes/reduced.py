"""Reduced model of one Hovershoe (paper eq. (4)-(9)), for planners, MPC and identification.

One shoe's state is :math:`s = (x, y, \\psi, \\theta, \\dot\\theta, \\dot\\psi, v)`: position
[m] and heading [rad] in the world's X-Y plane, forward (nose-down) pitch [rad], pitch and yaw
rates [rad/s] and forward speed [m/s]. Its inputs are the rider's toe torques
:math:`u = (u_\\theta, u_\\psi)` [N m] about the shoe's lateral (y) and vertical (z) axes:

.. math::

    J_\\theta \\ddot\\theta &= -c_1 \\theta - c_2 \\dot\\theta + u_\\theta  \\quad (4) \\\\
    J_\\psi \\ddot\\psi &= -c_3 \\dot\\psi + u_\\psi  \\quad (5) \\\\
    \\dot x &= v \\cos\\psi  \\quad (6) \\\\
    \\dot y &= v \\sin\\psi  \\quad (7) \\\\
    m \\dot v &= c_4 \\theta  \\quad (8)

Eq. (5) as printed in the paper reads :math:`-c_3\\psi`, a torsional *spring* pulling the
heading back to zero. We use the damping reading :math:`-c_3\\dot\\psi` because the paper's
own text calls :math:`c_3` "the coefficient for the ground contact damping term" and states
that nothing drives :math:`\\psi` back to zero (no internal yaw controller); a spring on the
absolute heading would make a shoe on the ground steer back to a fixed world direction,
which no tyre does. Physically :math:`c_3` is the tyre's rim friction resisting twist, here
linearised around the identified yaw rates. The simulated rim friction is Coulomb-like (it
sticks, then slides), so this linear law fits the held-out yaw rates to
:math:`r^2 \\approx 0.9`, the pitch to 0.999.

Every dynamics function takes an ``xp`` module (default :mod:`numpy`) and uses only
arithmetic and ``xp.sin``/``xp.cos``, so ``import casadi as xp`` reuses them symbolically;
they return tuples, which the caller stacks (``np.array`` or ``casadi.vertcat``).
"""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.hovershoes.parameters import HovershoesReducedParameters

__all__ = [
    "STATE_NAMES",
    "STATE_QUANTITIES",
    "contact_torques",
    "pitch_acceleration",
    "rollout",
    "shoe_dynamics",
    "speed_derivative",
    "yaw_acceleration",
]

STATE_NAMES: tuple[str, ...] = ("x", "y", "psi", "theta", "theta_dot", "psi_dot", "v")
# What each state is, by its canonical name (ridempc.boards.canonical): the same quantities
# every board's reduced model names.
STATE_QUANTITIES: dict[str, str] = {
    "x": "x",
    "y": "y",
    "psi": "heading",
    "theta": "pitch",
    "theta_dot": "pitch_rate",
    "psi_dot": "yaw_rate",
    "v": "speed",
}
Array = NDArray[np.float64]


def pitch_acceleration(
    theta: Any, theta_dot: Any, u_theta: Any, p: HovershoesReducedParameters
) -> Any:
    """Eq. (4): :math:`\\ddot\\theta = (-c_1\\theta - c_2\\dot\\theta + u_\\theta)/J_\\theta`.

    Args:
        theta: Forward pitch [rad].
        theta_dot: Pitch rate [rad/s].
        u_theta: Rider's pitch torque on the platform [N m].
        p: Reduced-model parameters.

    Returns:
        Pitch acceleration [rad/s^2].
    """
    return (-p.c1 * theta - p.c2 * theta_dot + u_theta) / p.J_theta


def yaw_acceleration(psi_dot: Any, u_psi: Any, p: HovershoesReducedParameters) -> Any:
    """Eq. (5), damping reading: :math:`\\ddot\\psi = (-c_3\\dot\\psi + u_\\psi)/J_\\psi`.

    Args:
        psi_dot: Yaw rate [rad/s].
        u_psi: Rider's yaw torque on the platform [N m].
        p: Reduced-model parameters.

    Returns:
        Yaw acceleration [rad/s^2].
    """
    return (-p.c3 * psi_dot + u_psi) / p.J_psi


def speed_derivative(theta: Any, p: HovershoesReducedParameters) -> Any:
    """Eq. (8): :math:`\\dot v = c_4\\theta / m` [m/s^2], for pitch ``theta`` [rad]."""
    return p.c4 * theta / p.m


def shoe_dynamics(
    state: Any,
    u: Any,
    p: HovershoesReducedParameters,
    xp: ModuleType = np,
) -> tuple[Any, ...]:
    """Eq. (4)-(8): :math:`\\dot s = f(s, u)` for one shoe.

    Args:
        state: :math:`(x, y, \\psi, \\theta, \\dot\\theta, \\dot\\psi, v)` (a sequence,
            an array or a CasADi vector), units as in
            :data:`STATE_NAMES` ([m], [m], [rad], [rad], [rad/s], [rad/s], [m/s]).
        u: :math:`(u_\\theta, u_\\psi)` [N m].
        p: Reduced-model parameters.
        xp: ``numpy`` or ``casadi``.

    Returns:
        The state derivative, in the order of :data:`STATE_NAMES`.
    """
    _, _, psi, theta, theta_dot, psi_dot, v = (state[i] for i in range(7))
    u_theta, u_psi = u[0], u[1]
    return (
        v * xp.cos(psi),  # (6)
        v * xp.sin(psi),  # (7)
        psi_dot,
        theta_dot,
        pitch_acceleration(theta, theta_dot, u_theta, p),  # (4)
        yaw_acceleration(psi_dot, u_psi, p),  # (5)
        speed_derivative(theta, p),  # (8)
    )


def contact_torques(
    positions: Sequence[Sequence[Any]], forces: Sequence[Sequence[Any]]
) -> tuple[Any, Any]:
    """Eq. (9): the rider's torques on one shoe from its foot contacts.

    .. math::

        \\begin{bmatrix} u_\\theta \\\\ u_\\psi \\end{bmatrix} =
        \\begin{bmatrix} 0 & 1 & 0 \\\\ 0 & 0 & 1 \\end{bmatrix}
        \\sum_i r_i \\times (-F_i)

    Args:
        positions: :math:`r_i` [m], each contact's position relative to the shoe, in the
            shoe's frame (x forward, y left, z up).
        forces: :math:`F_i` [N], the force the shoe applies on the rider at each contact, in
            the shoe's frame (so :math:`-F_i` is the rider's force on the shoe).

    Returns:
        :math:`(u_\\theta, u_\\psi)` [N m]. Arithmetic only, so works on CasADi symbols.
    """
    u_theta: Any = 0.0
    u_psi: Any = 0.0
    for r, f in zip(positions, forces, strict=True):
        # y and z components of r x (-f)
        u_theta = u_theta - (r[2] * f[0] - r[0] * f[2])
        u_psi = u_psi - (r[0] * f[1] - r[1] * f[0])
    return u_theta, u_psi


def rollout(
    p: HovershoesReducedParameters,
    initial: Sequence[float],
    u: Array,
    dt: float,
    substeps: int = 4,
) -> Array:
    """Integrate eq. (4)-(8) with RK4 under sampled inputs held over each sample.

    Args:
        p: Reduced-model parameters.
        initial: Initial state, in the order of :data:`STATE_NAMES`.
        u: Inputs :math:`(u_\\theta, u_\\psi)` at each sample [N m], shape (n, 2).
        dt: Sample period [s].
        substeps: RK4 steps per sample.

    Returns:
        States at each sample, shape (n, 7); row 0 is ``initial``.
    """
    n = len(u)
    out = np.empty((n, 7))
    s = np.asarray(initial, dtype=float)
    h = dt / substeps

    def f(state: Array, inp: Array) -> Array:
        return np.array(shoe_dynamics(state, inp, p))

    for k in range(n):
        out[k] = s
        for _ in range(substeps):
            k1 = f(s, u[k])
            k2 = f(s + 0.5 * h * k1, u[k])
            k3 = f(s + 0.5 * h * k2, u[k])
            k4 = f(s + h * k3, u[k])
            s = s + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return out
