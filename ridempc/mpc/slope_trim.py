"""The speed a rider loses on a slope, given back: an integral trim of the reference's speed.

The library's rides are on level ground. On a slope the shoes' firmware holds each shoe
pitched against the slope's pull, and the reduced model's balance of that pitch (eq. (4)
and (8), identified on level ground, where a pitched shoe accelerates) is not the slope's:
every plan predicts the shoes and the rider speeding up to the commanded speed, and the
next plan starts again from a rider who did not. Down 13 deg the rider settles 0.15-0.17 m/s
under a commanded 0.5 m/s and stays there. Whatever the model misses, a steady speed error
on a slope is taken out, as in offset-free tracking, by an integral of it laid over the
reference. The error a slope leaves grows with its pull, :math:`\\propto \\sin\\alpha`, so what
is integrated is the trim per unit of the slope's sine: while the slope :math:`\\hat\\alpha`
estimated under the platforms (:mod:`ridempc.mpc.slope`) has been steeper than ``GATE`` for
``HOLD`` and the MPC rides,

.. math:: \\dot\\kappa = \\frac{v_{cmd} - v}{T\\,|\\sin\\hat\\alpha|}, \\qquad
          \\delta = \\kappa\\,|\\sin\\hat\\alpha|, \\qquad |\\delta| \\le \\delta_{max},

so that the trim :math:`\\delta` [m/s] moves at :math:`(v_{cmd} - v)/T` on a steady slope and
goes with the slope where it ends (as the slope estimate reads level, within its window); on
level ground it is zero. A speed error over ``BAND`` is a transient and is not integrated,
nor one while the backup rides. The reference's speeds (the rider's and each platform's) are
raised by :math:`\\delta` and its positions moved on by :math:`\\delta\\,t` over the horizon
along the platforms' heading (:class:`SlopeTrim`, a problem shaper).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.manoeuvre import MOVING, RETARGET_BAND, StateLayout
from ridempc.mpc.problem import MpcProblem

if TYPE_CHECKING:  # the build's inputs carry the shoes' observer, which holds a trim
    from ridempc.mpc.stages.build import BuildInputs

__all__ = ["BAND", "GATE", "HOLD", "LIMIT", "TIME_CONSTANT", "SlopeSpeedTrim", "SlopeTrim"]

Array = NDArray[np.float64]

# [rad] 3 deg: ten times what the slope estimate reads on level ground (0.1-0.3 deg before
# the crest of `slope-down-13`), a third of the gentlest slope a scenario rides (7 deg).
GATE: float = math.radians(3.0)
# [s] a slope is one the estimate has read beyond the gate this long: a step's edge or a bump
# passes under it sooner (the estimate passes 3 deg for moments on level ground); 0.3 s, the
# time constant of the velocity-borne slope estimate this trim was measured with (session 10)
HOLD: float = 0.3
# [s] twice the rider's speed response (a 0.2 m/s step of the command is ridden within
# 0.5 s: the library's 0.8 s per m/s plus its lean), so the trim does not ring with it;
# short against the 6 s a ride spends on a 3 m slope.
TIME_CONSTANT: float = 1.0
# [m/s] the trim at most: within the 0.5 m/s between the library's speeds (0.5, 1.0, 1.5), so a
# trimmed reference stays within a step of the library's; twice the steady error measured down
# 13 deg (0.15-0.17 m/s).
LIMIT: float = 0.3
# [m/s] a speed error larger than this is a transient (a crest's run-off, a push), which
# the plan rides out, not the slope's steady offset: the manoeuvres' own band for a new speed
BAND: float = RETARGET_BAND


class SlopeSpeedTrim:
    """The reference's speed trim :math:`\\delta` [m/s] (the module docstring).

    Args:
        gate: The slope beyond which the trim integrates [rad].
        time_constant: :math:`T` [s].
        limit: :math:`\\delta_{max}` [m/s].
    """

    def __init__(
        self, gate: float = GATE, time_constant: float = TIME_CONSTANT, limit: float = LIMIT
    ) -> None:
        if not (gate > 0.0 and time_constant > 0.0 and limit > 0.0):
            raise ValueError(
                f"slope trim: gate {gate}, time_constant {time_constant} and limit {limit} "
                "must be > 0"
            )
        self.gate, self.time_constant, self.limit = gate, time_constant, limit
        self.value = 0.0  # [m/s] the trim
        self.per_slope = 0.0  # [m/s] the trim per unit of the slope's sine
        self._sloped = 0.0  # [s] how long the estimate has been beyond the gate
        self._time: float | None = None

    def reset(self) -> None:
        self.value = self.per_slope = self._sloped = 0.0
        self._time = None

    def update(
        self,
        time: float,
        wanted: float,
        speed: float,
        slopes: Sequence[float],
        riding: bool = True,
    ) -> float:
        """Fold in one tick; returns the trim [m/s].

        Args:
            time: The tick's time [s].
            wanted: The commanded speed [m/s].
            speed: The rider's forward speed [m/s] (her centre of mass's).
            slopes: The slope under each platform [rad] (positive uphill).
            riding: Whether the MPC rides (else the trim is held: the backup's speed is not
                the plan's).
        """
        dt = 0.0 if self._time is None else max(0.0, time - self._time)
        self._time = time
        slope = abs(math.sin(sum(slopes) / len(slopes))) if slopes else 0.0
        self._sloped = self._sloped + dt if slope > math.sin(self.gate) else 0.0
        if self._sloped < HOLD or wanted < MOVING:
            self.value = 0.0  # level ground (or rest): the library's ride
            return self.value
        error = wanted - speed
        if riding and abs(error) < BAND:  # a larger error is a transient, not the offset
            bound = self.limit / slope
            rate = error / (self.time_constant * slope)
            self.per_slope = min(max(self.per_slope + rate * dt, -bound), bound)
        self.value = self.per_slope * slope
        return self.value


class SlopeTrim:
    """The reference's speeds raised by the shoes' observer's trim (its frozen copy in the
    build's inputs) and its positions moved on with them (a problem shaper).

    Args:
        layout: Where the rider's states are (``com_x``, ``com_y``, ``vx``, ``vy``).
        columns: Per platform, its (x, y, heading, speed) columns in the MPC's state.
    """

    def __init__(self, layout: StateLayout, columns: Sequence[Sequence[int]]) -> None:
        names = layout.names
        self._rider = (names["com_x"], names["com_y"], names["vx"], names["vy"])
        self._columns = tuple(tuple(c) for c in columns)

    def __call__(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        shoes = inputs.shoes
        trim = shoes.trim.value if shoes is not None else 0.0
        if trim == 0.0 or not self._columns:
            return problem
        states = self.lay_over(problem.state_reference, trim, problem.dt)
        return replace(problem, state_reference=states)

    def lay_over(self, states: Array, trim: float, dt: float) -> Array:
        """A copy of the reference ``states`` (nodes x nx, ``dt`` [s] apart) moving ``trim``
        [m/s] faster along the platforms' mean heading from its first node on: the node at
        the estimate (node 0, which the plan does not weigh) stays the library's, as the
        handover's deviation of the rider from it (:func:`~ridempc.mpc.handover.deviation`)
        is the model's, not the trim's."""
        out = np.array(states, dtype=float)
        ahead = trim * dt * np.arange(len(out))  # [m] how much further at each node
        heading = np.mean([out[:, c[2]] for c in self._columns], axis=0)
        cos, sin = np.cos(heading), np.sin(heading)
        com_x, com_y, vx, vy = self._rider
        out[:, com_x] += ahead * cos
        out[:, com_y] += ahead * sin
        out[1:, vx] += trim * cos[1:]
        out[1:, vy] += trim * sin[1:]
        for x, y, own, speed in self._columns:
            out[:, x] += ahead * np.cos(out[:, own])
            out[:, y] += ahead * np.sin(out[:, own])
            out[1:, speed] += trim
        return out
