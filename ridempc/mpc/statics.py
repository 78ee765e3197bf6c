"""A commanded state laid over the reference so that the reference stays in balance.

A command that moves one state away from the library's trajectory (the skateboard's deck
roll :math:`\\theta^*`) leaves the rest of the reference where the library had it: the
rider centred over the deck and the forces even. Such a reference is not an equilibrium
(the trucks' stiffness :math:`K_B \\theta` [N m] must be held by a sideways shift of the
load), so the MPC trades the roll error against the distance to a reference it can never
reach, and tracks the roll late and short (deck roll 0.77 of the commanded amplitude,
0.36 s late, on the dog's 0.1 rad, 3 s roll-tracking).

:func:`static_shift` gives the least change of the reference per unit change of the
commanded state :math:`x_c` that keeps the force-driven accelerations as they were. With the
continuous model :math:`\\dot x = f(x, u)` linearised at the reference,
:math:`A^c = \\partial_x f`, :math:`B^c = \\partial_u f`, the rows :math:`r` whose rates the
forces drive (the rider's linear and angular accelerations, the board's speed and roll
rate), the free states :math:`s` (the rider's position and attitude) and the force inputs
:math:`F`:

.. math::

    \\min_{\\delta x_s, \\delta u_F} \\tfrac12 \\left(\\delta x_s^\\top Q_s \\delta x_s
        + \\delta u_F^\\top R_F \\delta u_F\\right)
    \\quad \\text{s.t.} \\quad
    A^c_{r s} \\delta x_s + B^c_{r F} \\delta u_F = -A^c_{r c}

with :math:`Q, R` the MPC's weights, whose solution is
:math:`z = W^{-1} M^\\top (M W^{-1} M^\\top)^+ (-A^c_{rc})`,
:math:`M = [A^c_{rs}\\; B^c_{rF}]`, :math:`W = \\mathrm{diag}(Q_s, R_F)`. The reference
then moves by :math:`(\\delta x, \\delta u)\\,(x^*_{c,k} - \\bar x_{c,k})` at each step
:math:`k`. A commanded state that moves, at :math:`\\dot x^*_c`, moves the free states at
:math:`\\delta x_s \\dot x^*_c`: the velocities :math:`v` (the other states in the free
states' rows, :math:`\\dot x_s = A^c_{s v} v`) change by the least-squares
:math:`\\delta v` of :math:`A^c_{sv} \\delta v = \\delta x_s` per unit of
:math:`\\dot x^*_c` (a reference rolling the deck sways the rider, not only leans it).

For the dog on the deck (:math:`K_B` = 48 N m/rad) 0.1 rad of roll moves the CoM 5.5 cm
to the low side; the forces change by under 1 N, because the model holds the feet's lever
arms from the CoM, so the shifted CoM carries its weight's moment onto the deck.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["StaticShift", "static_shift"]

Array = NDArray[np.float64]
_ZERO = 1e-9


class StaticShift(NamedTuple):
    """The reference's change per unit of the commanded state and of its rate.

    Attributes:
        states: :math:`\\delta x` (nx), per unit of the commanded state.
        inputs: :math:`\\delta u` (nu), per unit of the commanded state.
        velocities: :math:`\\delta v` (nx), per unit of the commanded state's rate.
    """

    states: Array
    inputs: Array
    velocities: Array


def static_shift(
    a_c: Array,
    b_c: Array,
    changed: int,
    free_states: Sequence[int],
    force_inputs: Sequence[int],
    state_weights: Array,
    input_weights: Array,
) -> StaticShift:
    """The reference's change per unit change of state ``changed`` (module docstring).

    Args:
        a_c: :math:`A^c` at the reference (nx x nx).
        b_c: :math:`B^c` at the reference (nx x nu).
        changed: Index of the commanded state.
        free_states: Indices of the states the reference may move (the rider's pose).
        force_inputs: Indices of the force inputs.
        state_weights: Diagonal of :math:`Q` (nx), positive on ``free_states``.
        input_weights: Diagonal of :math:`R` (nu), positive on ``force_inputs``.

    Returns:
        :math:`\\delta x` (zero but on ``free_states``), :math:`\\delta u` (zero but on
        ``force_inputs``) and :math:`\\delta v` (zero but on the free states' velocities).
    """
    free, forces = np.asarray(free_states, dtype=int), np.asarray(force_inputs, dtype=int)
    rows = np.nonzero(np.abs(b_c[:, forces]).max(axis=1) > _ZERO)[0]
    m = np.hstack([a_c[np.ix_(rows, free)], b_c[np.ix_(rows, forces)]])
    w_inv = 1.0 / np.concatenate([state_weights[free], input_weights[forces]])
    gram = (m * w_inv) @ m.T
    z = w_inv * (m.T @ (np.linalg.pinv(gram) @ -a_c[rows, changed]))
    dx, du = np.zeros(a_c.shape[0]), np.zeros(b_c.shape[1])
    dx[free], du[forces] = z[: free.size], z[free.size :]
    velocity = np.setdiff1d(np.nonzero(np.abs(a_c[free]).max(axis=0) > _ZERO)[0], free)
    dv = np.zeros(a_c.shape[0])
    if velocity.size:
        dv[velocity] = np.linalg.lstsq(a_c[np.ix_(free, velocity)], dx[free], rcond=None)[0]
    return StaticShift(dx, du, dv)
