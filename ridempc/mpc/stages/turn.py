"""The turn the ride has been commanded so far, which the reference and the library frame
carry: the reference's headings are turned by it
(:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.with_turn`), and the estimate's headings,
which wrap at :math:`\\pm\\pi`, are unwrapped to it (the commanded turn does not wrap)."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
from numpy.typing import NDArray

__all__ = ["TurnSoFar"]

Array = NDArray[np.float64]


class TurnSoFar:
    """The commanded yaw rate integrated over the ride, :math:`\\int \\omega^* dt` [rad],
    each MPC tick's rate held until the next (the first step's of the horizon)."""

    def __init__(self) -> None:
        self.turned = 0.0  # [rad]
        self._time: float | None = None
        self._rate = 0.0

    def advance(self, now: float, rate: float) -> float:
        """The turn at ``now`` [s], the rate [rad/s] from ``now`` on being ``rate``."""
        if self._time is not None:
            self.turned += self._rate * (now - self._time)
        self._time, self._rate = now, rate
        return self.turned

    def unwrapped(self, x0: Array, reference: Array, headings: Iterable[int]) -> Array:
        """``x0`` with each heading (at ``headings``: the base's yaw, the platforms') [rad]
        within :math:`\\pi` of the ``reference`` state's turned by the turn so far."""
        out = x0.copy()
        for i in headings:
            target = reference[i] + self.turned
            out[i] = target + math.remainder(x0[i] - target, 2.0 * math.pi)
        return out
