"""Reduced model of the skateboard (skateboard paper, eqs. 6-7 and 11-14).

Two parts, as in the paper:

**Deck roll** (eqs. 6-7). The bushings act on the deck as a roll spring-damper,

.. math:: \\mathcal{I}(\\varphi, \\psi) = -K_B \\varphi - B_B \\psi \\quad (6)

and the deck's roll obeys :math:`I_{Bx} \\dot\\psi = \\tau + \\mathcal{I}(\\varphi, \\psi)`,
:math:`\\dot\\varphi = \\psi` (the roll row of eq. 7), where :math:`\\varphi` is the deck roll
[rad], :math:`\\psi` its rate [rad/s] and :math:`\\tau` [N m] the roll torque the rider puts
on the deck: :math:`\\tau = -(R_B^\\top \\sum_i r_{B_i} \\times f_i)_x` with the foot forces
:math:`f_i` on the robot and the feet :math:`r_{B_i}` from the deck's top centre (eq. 7-8),
plus any other scripted torque about the deck's x axis.

**Steering** (eqs. 11-14). A truck whose kingpin leans by the rake :math:`\\gamma` from the
deck normal steers by :math:`\\delta` when the deck rolls by :math:`\\varphi`:

.. math:: \\sin\\varphi \\cot\\gamma_{f/r} = \\tan\\delta_{f/r} \\quad (11)

With the front axle at :math:`l_f` ahead of and the rear axle :math:`l_r` behind the point
:math:`C_B` of zero lateral velocity, each axle moves along its wheels (no side slip):

.. math:: v^B_{f_y} = -v \\tan\\delta_f = v^B_y + \\omega l_f, \\qquad
          v^B_{r_y} = v \\tan\\delta_r = v^B_y - \\omega l_r \\quad (13)

(the rear truck, mirrored, steers the other way). With :math:`v^B_y = 0` at :math:`C_B`,
:math:`l_f / l_r = \\tan\\delta_f / \\tan\\delta_r = \\cot\\gamma_f / \\cot\\gamma_r` (12), and
subtracting the two rows of (13), with :math:`l_f + l_r = L` the wheelbase:

.. math:: \\omega = -\\frac{v (\\tan\\delta_f + \\tan\\delta_r)}{L}
                  = -\\frac{v \\sin\\varphi}{K_{board}}, \\qquad
          K_{board} = \\frac{l_f}{\\cot\\gamma_f} = \\frac{l_r}{\\cot\\gamma_r}
                    = \\frac{L}{\\cot\\gamma_f + \\cot\\gamma_r}

which is eq. (14), :math:`\\sin\\varphi\\, v + K_{board}\\, \\omega = 0`. Signs: the roll is
about the deck's forward x axis (positive lowers the right, -y, edge), the yaw rate about
the world's up z axis; leaning right turns right. :math:`C_B` then follows the Dubins-like
kinematics :math:`\\dot x = v \\cos\\psi_z`, :math:`\\dot y = v \\sin\\psi_z`,
:math:`\\dot\\psi_z = \\omega`.

The dynamics functions take an ``xp`` module (default :mod:`numpy`) and use only arithmetic
and ``xp.sin``/``xp.cos``/``xp.tan``, so that CasADi (``import casadi as xp``) can reuse them.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any

import numpy as np
from scipy.linalg import expm

from ridempc.boards.skateboard.parameters import SkateboardParameters, SkateboardReducedParameters

__all__ = [
    "board_length",
    "dubins_rates",
    "roll_acceleration",
    "roll_rates",
    "simulate_roll",
    "steering_angle_tangent",
    "steering_axle_distances",
    "steer_gain",
    "yaw_rate",
]


def steering_angle_tangent(roll: Any, rake: float, xp: ModuleType = np) -> Any:
    """Eq. (11): :math:`\\tan\\delta = \\sin\\varphi \\cot\\gamma`.

    Args:
        roll: Deck roll :math:`\\varphi` [rad].
        rake: Truck rake :math:`\\gamma`, kingpin axis from the deck normal [rad].
        xp: Array module (numpy or casadi).

    Returns:
        :math:`\\tan\\delta` of that truck's steering angle [-].
    """
    return xp.sin(roll) * xp.cos(rake) / xp.sin(rake)


def board_length(rake_front: float, rake_rear: float, wheelbase: float) -> float:
    """Eq. (12)-(14): :math:`K_{board} = L / (\\cot\\gamma_f + \\cot\\gamma_r)` [m].

    Args:
        rake_front: Front rake :math:`\\gamma_f` [rad].
        rake_rear: Rear rake :math:`\\gamma_r` [rad].
        wheelbase: Axle-to-axle distance :math:`L` [m].
    """
    return wheelbase / (1.0 / math.tan(rake_front) + 1.0 / math.tan(rake_rear))


def steering_axle_distances(
    rake_front: float, rake_rear: float, wheelbase: float
) -> tuple[float, float]:
    """Eq. (12): :math:`(l_f, l_r) = K_{board} (\\cot\\gamma_f, \\cot\\gamma_r)` [m],
    the axles' distances from the point :math:`C_B` of zero lateral velocity."""
    k = board_length(rake_front, rake_rear, wheelbase)
    return k / math.tan(rake_front), k / math.tan(rake_rear)


def steer_gain(params: SkateboardParameters) -> float:
    """The geometric kinematic gain :math:`1 / K_{board}` of a board [1/m]."""
    return 1.0 / board_length(
        math.radians(params.rake_front), math.radians(params.rake_rear), params.wheelbase
    )


def yaw_rate(speed: Any, roll: Any, gain: float, xp: ModuleType = np) -> Any:
    """Eq. (14): :math:`\\omega = -v \\sin\\varphi / K_{board}`.

    Args:
        speed: Forward speed :math:`v` of :math:`C_B` along the deck's heading [m/s].
        roll: Deck roll :math:`\\varphi` about its forward axis [rad].
        gain: :math:`1 / K_{board} = (\\cot\\gamma_f + \\cot\\gamma_r) / L` [1/m].
        xp: Array module (numpy or casadi).

    Returns:
        Yaw rate about the world's up axis [rad/s].
    """
    return -gain * speed * xp.sin(roll)


def dubins_rates(heading: Any, speed: Any, roll: Any, gain: float, xp: ModuleType = np) -> Any:
    """Dubins-like kinematics of :math:`C_B`: :math:`(\\dot x, \\dot y, \\dot\\psi_z)`.

    :math:`\\dot x = v \\cos\\psi_z`, :math:`\\dot y = v \\sin\\psi_z` [m/s],
    :math:`\\dot\\psi_z = -v \\sin\\varphi / K_{board}` [rad/s] (eq. 14).

    Args:
        heading: Deck heading (yaw) :math:`\\psi_z` [rad].
        speed: Forward speed :math:`v` [m/s].
        roll: Deck roll :math:`\\varphi` [rad].
        gain: :math:`1 / K_{board}` [1/m].
        xp: Array module (numpy or casadi).
    """
    return (
        speed * xp.cos(heading),
        speed * xp.sin(heading),
        yaw_rate(speed, roll, gain, xp),
    )


def roll_acceleration(
    roll: Any, roll_rate: Any, torque: Any, inertia: Any, stiffness: Any, damping: Any
) -> Any:
    """Eqs. (6)-(7): :math:`\\dot\\psi = (\\tau - K_B \\varphi - B_B \\psi) / I_{Bx}` [rad/s^2].

    Args:
        roll: Deck roll :math:`\\varphi` [rad].
        roll_rate: Deck roll rate :math:`\\psi` [rad/s].
        torque: Rider's (and any other) roll torque on the deck :math:`\\tau` [N m].
        inertia: Deck roll inertia :math:`I_{Bx}` [kg m^2].
        stiffness: Bushing roll stiffness :math:`K_B` [N m / rad].
        damping: Bushing roll damping :math:`B_B` [N m s / rad].
    """
    bushing = -stiffness * roll - damping * roll_rate  # eq. (6)
    return (torque + bushing) / inertia


def roll_rates(state: Any, torque: Any, reduced: SkateboardReducedParameters) -> Any:
    """Eq. (7), roll rows: :math:`(\\dot\\varphi, \\dot\\psi)` of ``state`` = (roll, roll rate)."""
    return state[1], roll_acceleration(
        state[0],
        state[1],
        torque,
        reduced.roll_inertia,
        reduced.roll_stiffness,
        reduced.roll_damping,
    )


def simulate_roll(
    times: np.ndarray,
    torque: np.ndarray,
    initial: tuple[float, float],
    inertia: float,
    stiffness: float,
    damping: float,
) -> np.ndarray:
    """Integrate eq. (7)'s roll rows under a sampled torque (exact zero-order hold).

    Args:
        times: Uniform sample times [s], shape (n,).
        torque: Roll torque held over each interval [N m], shape (n,).
        initial: Roll [rad] and roll rate [rad/s] at ``times[0]``.
        inertia: :math:`I_{Bx}` [kg m^2].
        stiffness: :math:`K_B` [N m / rad].
        damping: :math:`B_B` [N m s / rad].

    Returns:
        Roll and roll rate at ``times``, shape (n, 2).
    """
    dt = float(times[1] - times[0])
    continuous = np.zeros((3, 3))
    continuous[0, 1] = 1.0
    continuous[1] = [-stiffness / inertia, -damping / inertia, 1.0 / inertia]
    discrete = expm(continuous * dt)
    ad, bd = discrete[:2, :2], discrete[:2, 2]
    states = np.empty((len(times), 2))
    states[0] = initial
    for k in range(len(times) - 1):
        states[k + 1] = ad @ states[k] + bd * torque[k]
    return states
