"""An external-impulse observer: the push the rider's own contact forces do not explain.

The rider's linear momentum changes only by the forces on it: its contacts' and gravity,
and whatever pushes it from outside,

.. math:: m\\, \\dot c = \\textstyle\\sum_i f_i + m g + f_{ext},

with :math:`c` the centre of mass [m], :math:`f_i` the support's force on each foot [N] and
:math:`g` gravity [m/s^2]. The rider's own manoeuvres (a lean, a speed step, a push-off) are
made by its contact forces; a push is not. The residual of the balance over a window
:math:`T`, per kg,

.. math:: \\Delta v_{ext}(t) = \\dot c(t) - \\dot c(t - T)
          - \\int_{t-T}^{t} \\big(\\textstyle\\sum_i f_i / m + g\\big)\\, dt,

is the velocity change [m/s] (the impulse per mass [N s/kg]) nothing the rider commanded
explains: the generalised-momentum observer's residual on the centroidal rows, integrated
rather than low-passed so that a short push reads as its whole impulse. :math:`\\dot c` comes
from the state estimate (the whole-body QP's model, evaluated there each tick) and
:math:`f_i` from the forces the whole-body QP commanded, so
nothing here reads the simulator's truth. Only its horizontal part is used: the pushes
that throw a rider are horizontal, and the vertical row carries the unknown payload's weight.

A slow residual (a commanded force the motors do not quite realise, a payload's share of a
speed change) is not a push: its mean over :data:`BASELINE_S` *before* the window (the
samples leaving it) is taken off what the window sums, so that a push inside the window does
not take itself off; once it has left, it lowers the baseline by its impulse over
:data:`BASELINE_S` (a 0.4 m/s push: 0.2 m/s^2, 0.08 m/s over the window, decaying).

:class:`ImpulseTrigger` hands the ride to the backup when the horizontal impulse exceeds the
pair's ``band`` [m/s] (the ``impulse`` stage): a velocity change beyond the region the MPC's
linear model rides, which the PD then rides out.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from numpy.typing import NDArray

from ridempc.gravity import GRAVITY_WORLD as GRAVITY

__all__ = [
    "BASELINE_S",
    "GRAVITY",
    "WINDOW_S",
    "ImpulseObserver",
    "ImpulseTrigger",
]

Array = NDArray[np.float64]
# [s] the window the impulse is summed over: twice the push (0.2 s), so a push's
# whole impulse is counted, and about one divergence time of a rider (Cassie's 0.3 s), so
# a slow drift the disturbance observer takes up does not add up to a push
WINDOW_S: float = 0.4
# [s] the slow residual (the forces the motors realise short of the commanded ones) taken
# off: its mean over a rider's sway (~1-2 s), long against a push
BASELINE_S: float = 2.0


class ImpulseObserver:
    """:math:`\\Delta v_{ext}` over the last :attr:`window_s`, tick by tick.

    Args:
        mass: The rider's mass [kg].
        window_s: :math:`T` [s].
        baseline_s: The slow residual's time constant [s].

    Attributes:
        impulse: The latest :math:`\\Delta v_{ext}` [m/s], world frame, shape (3,).
        peak: The largest horizontal :math:`|\\Delta v_{ext}|` so far [m/s].
        peak_time: When it was read [s] (None before any).
    """

    def __init__(
        self,
        mass: float,
        window_s: float = WINDOW_S,
        baseline_s: float = BASELINE_S,
    ) -> None:
        if mass <= 0.0:
            raise ValueError(f"mass must be positive, got {mass}")
        self.mass = mass
        self.window_s = window_s
        self.baseline_s = baseline_s
        self.impulse = np.zeros(3)
        self.peak = 0.0
        self.peak_time: float | None = None
        self._baseline = np.zeros(3)  # [m/s^2] the slow residual, from before the window
        # (time [s], the step [s], the residual [m/s]) of each tick in the window
        self._samples: deque[tuple[float, float, Array]] = deque()
        self._summed = np.zeros(3)  # [m/s] the window's residuals, summed as they come and go
        self._span = 0.0  # [s] the window's steps, summed likewise
        self._last: tuple[float, Array, Array] | None = None  # time, velocity, force

    def reset(self) -> None:
        """Forget the window (the forces commanded were not the ones applied: another law
        rode); the baseline is kept."""
        self._samples.clear()
        self._summed = np.zeros(3)
        self._span = 0.0
        self._last = None
        self.impulse = np.zeros(3)

    def update(self, time: float, velocity: Array, force: Array) -> Array:
        """:math:`\\Delta v_{ext}` [m/s] with the centre of mass at ``velocity`` [m/s] at
        ``time`` [s], and ``force`` [N] the sum of the contact forces commanded from now to
        the next update (world frame)."""
        velocity = np.asarray(velocity, dtype=float)
        force = np.asarray(force, dtype=float)
        last, self._last = self._last, (time, velocity, force)
        if last is None or time <= last[0]:
            return self.impulse
        step = time - last[0]
        explained = (last[2] / self.mass + GRAVITY) * step
        residual = velocity - last[1] - explained
        self._samples.append((time, step, residual))
        self._summed += residual
        self._span += step
        while self._samples and self._samples[0][0] <= time - self.window_s:
            _, left, residual = self._samples.popleft()
            self._summed -= residual
            self._span -= left
            if self.baseline_s > 0.0:
                share = min(1.0, left / self.baseline_s)
                self._baseline += share * (residual / left - self._baseline)
        self.impulse = self._summed - self._baseline * self._span
        if _horizontal(self.impulse) > self.peak:
            self.peak, self.peak_time = _horizontal(self.impulse), time
        return self.impulse


class ImpulseTrigger:
    """The rule: hand over when the horizontal impulse per mass leaves an ellipse of
    half-axes ``band`` along the rider's heading and ``sideways`` across it [m/s],

    .. math:: (\\Delta v_{along} / b)^2 + (\\Delta v_{across} / b_s)^2 > 1:

    a board's support differs along its travel (its wheels drive under the rider) and
    across it (the rider's stance on the deck), and so does the push its MPC rides.

    Args:
        band: The largest velocity change [m/s] along the heading the MPC rides (the pair's
            ``impulse.band``).
        sideways: The same across it [m/s] (None: ``band``).
    """

    def __init__(self, band: float, sideways: float | None = None) -> None:
        sideways = band if sideways is None else sideways
        if band <= 0.0 or sideways <= 0.0:
            raise ValueError(f"bands must be positive, got {band} and {sideways}")
        self.band = band
        self.sideways = sideways

    def __call__(self, impulse: Array, heading: float = 0.0) -> str | None:
        """Why the MPC cannot ride ``impulse`` [m/s] (world frame) with the rider heading
        ``heading`` [rad] (world yaw), or None if it can."""
        c, s = math.cos(heading), math.sin(heading)
        along = c * impulse[0] + s * impulse[1]
        across = -s * impulse[0] + c * impulse[1]
        if math.hypot(along / self.band, across / self.sideways) <= 1.0:
            return None
        towards = math.degrees(math.atan2(across, along))
        return (
            f"pushed by {_horizontal(impulse):.2g} m/s towards {towards:.0f} deg of its heading "
            f"(bands {self.band:g} along, {self.sideways:g} across)"
        )


def _horizontal(impulse: Array) -> float:
    return float(math.hypot(impulse[0], impulse[1]))
