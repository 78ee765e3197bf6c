"""The MPC's forces low-passed from one solve to the next, before the whole-body QP gets them.

On the Hovershoes the MPC's first input jumps from one 30 Hz solve to the next: each solve
answers a new estimate of the shoes' pitch and pitch rate, whose one-step prediction is poor.
Passed on to the toes by the whole-body QP, the steps make the toes and the shoes' pitch
loops ring at 7-9 Hz (measurements: ``docs/tuning.md``).

The forces the whole-body QP is given, :math:`\\bar u`, follow the plan's first input
:math:`u_0` through a first-order low-pass with time constant :math:`\\tau` [s]:

.. math::

    \\bar u_k = \\bar u_{k-1} + \\alpha (u_{0,k} - \\bar u_{k-1}), \\qquad
    \\alpha = 1 - e^{-\\Delta t / \\tau}

with :math:`\\Delta t` [s] the time since the last solve (0.03 s at the rider's 33.3 Hz).
The first solve passes through.

The filter is for pairs whose feet do not swing (the Hovershoes): it would hold a force on
a foot the schedule lifts.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["ForceFilter"]

Array = NDArray[np.float64]


class ForceFilter:
    """First-order low-pass of the MPC's first input (module docstring).

    Args:
        time_constant: :math:`\\tau` [s], positive.

    Raises:
        ValueError: A time constant that is not positive and finite.
    """

    def __init__(self, time_constant: float) -> None:
        if not (math.isfinite(time_constant) and time_constant > 0.0):
            raise ValueError(f"force filter: time constant {time_constant} s must be positive")
        self.time_constant = float(time_constant)
        self._value: Array | None = None
        self._time = 0.0

    def __call__(self, u: Array, now: float) -> Array:
        """:math:`\\bar u` after the solve at ``now`` [s] gave ``u``."""
        u = np.asarray(u, dtype=float)
        if self._value is None or self._value.shape != u.shape:
            self._value = u.copy()
        else:
            alpha = 1.0 - math.exp(-max(now - self._time, 0.0) / self.time_constant)
            self._value = self._value + alpha * (u - self._value)
        self._time = now
        return self._value.copy()
