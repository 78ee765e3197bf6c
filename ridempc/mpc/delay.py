"""The MPC's start predicted over its computation delay (delay-compensated plans).

A plan solved from the state estimated at the MPC's tick is taken up ``plan_latency`` ticks
later (:class:`~ridempc.mpc.rider.MpcRider`): meanwhile the loop follows the plan in force,
applying its first input. The standard compensation of a computation delay solves the new
plan from the state *predicted at its take-up* instead, so the plan starts where the
rider will be when it takes over and a latency costs no phase:

.. math::
    \\hat x(t + \\tau) = \\hat x(t) + \\tau \\, (f(\\hat x(t), u^{\\mathrm{prev}}_0, p(t))
    + \\Delta f)

with the reduced model's rates :math:`f` (:class:`~ridempc.mpc.problem.LinearModel`), the
previous plan's first input :math:`u^{\\mathrm{prev}}_0`, the mode parameters of the
reference at the take-up and the estimated drift :math:`\\Delta f`. One forward-Euler step:
the delay (2-4 ms) is a hundredth of the slowest modes the MPC stabilises (a deck's roll,
a platform's pitch, 0.3-1 s), so a higher-order step changes the prediction by less than
the estimate's noise.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.problem import LinearModel
from ridempc.mpc.reference import MotionReference

__all__ = ["predicted_start"]

Array = NDArray[np.float64]


def predicted_start(
    model: LinearModel,
    reference: MotionReference,
    t_ref: float,
    x0: Array,
    u_prev: Array,
    drift: Array | None,
    delay: float,
    dt: float,
) -> Array:
    """The state ``delay`` [s] after ``x0``, the previous plan's input applied (module
    docstring).

    Args:
        model: The pair's reduced model.
        reference: The reference tracked, for the mode parameters :math:`p(t)`.
        t_ref: The reference's time of ``x0`` [s].
        x0: The mapped estimate at the MPC's tick (nx), the pair's state layout.
        u_prev: The first input of the plan in force (nu), what the loop applies until
            the new plan takes over.
        drift: The estimated drift of the rates (nx), or None.
        delay: Time from the tick to the plan's take-up :math:`\\tau` [s].
        dt: The MPC's step [s] (the reference's window is sampled over one step).

    Returns:
        :math:`\\hat x(t + \\tau)` (nx); ``x0`` itself when ``delay`` is 0.
    """
    if delay == 0.0:
        return x0
    window = reference.sample(t_ref, 1, dt)
    rates, _, _ = model.evaluate(x0, np.asarray(u_prev, dtype=float)[None, :], window.parameters)
    velocity = rates[0] if drift is None else rates[0] + drift
    return np.asarray(x0 + delay * velocity, dtype=float)
