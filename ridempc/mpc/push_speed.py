"""The held speed's outer loop: a PI over the re-pushes, on the board's speed over a stroke.

A rider holding a commanded speed :math:`v^*` [m/s] on a board only a push drives pushes
again from the rolling board (the library's ``repush`` entries) once it has slowed. Each
re-push's strokes are laid to add the entry's gain (:data:`~ridempc.mpc.manoeuvre.REPUSH_BAND`)
against rolling resistance; a stroke that falls short of it (a rolled deck in a turn, a
board slower than the entry's rolling start) leaves the board slower, and nothing asked it
back: the speed decayed re-push by re-push.

So an outer loop, the standard cascade over an inner tracking loop, measures the speed the
strokes hold and asks the next re-push for more. Its error is the command against the
board's speed averaged over one stroke's period :math:`T_s`,

.. math:: e = v^* - \\bar v, \\qquad \\bar v = \\frac{1}{T_s} \\int_{t - T_s}^{t} v\\, dt,

(the average spans one stroke and the coast between two, so the speed a stroke gives and
rolling resistance takes off again do not move it), and its output is the speed a re-push
is asked to add beyond its entry's gain,

.. math:: u = \\mathrm{clip}(K_p e + I, 0, u_{max}), \\qquad
    \\dot I = e / T_i, \\quad I \\in [0, u_{max}],

used twice: a coasting board is pushed again :math:`u` sooner (at :math:`v^* -`
``REPUSH_BAND`` :math:`+ u`), and the re-push's reference asks for :math:`u` more over its
ground time (:mod:`~ridempc.mpc.push_gain`). The loop integrates only while the ride holds
its speed after the push-off (a push-off from rest is not a shortfall), and never below
zero: a board faster than the command coasts down to it.
"""

from __future__ import annotations

from collections import deque

__all__ = [
    "GAIN_LIMIT",
    "INTEGRAL_TIME",
    "PROPORTIONAL",
    "ROLLING_DECELERATION",
    "STROKE_PERIOD",
    "StrokeSpeedLoop",
]

# [s] one stroke and the coast after it: the library's skate entries lay their strokes at
# this period (the trajopt's ``period`` option of both skateboard pairs)
STROKE_PERIOD: float = 1.2
# [m/s^2] the coasting deceleration of a rider on the deck by rolling resistance (the board
# measured coasting straight, 0.14 m/s^2, docs/tuning.md): what each stroke must replace
ROLLING_DECELERATION: float = 0.14
# [-] a re-push is asked back the shortfall measured over the last stroke, all of it: one
# stride of strokes is the loop's sample, as a deadbeat step asks a sample's error back
PROPORTIONAL: float = 1.0
# [s] a persistent shortfall is asked back once more per stroke period: the integral time
# is the loop's sampling period, the slowest a stroke-by-stroke loop can act
INTEGRAL_TIME: float = STROKE_PERIOD
# [m/s] the most a re-push is asked beyond its entry: what rolling resistance takes over one
# stroke's period (one stroke's loss replaced twice in a stride of two), 0.17 m/s
GAIN_LIMIT: float = ROLLING_DECELERATION * STROKE_PERIOD


class StrokeSpeedLoop:
    """The PI of the held speed (see the module docstring).

    Args:
        period: The averaging window :math:`T_s` [s].
        proportional: :math:`K_p` [-].
        integral_time: :math:`T_i` [s].
        limit: :math:`u_{max}` [m/s].
    """

    def __init__(
        self,
        period: float = STROKE_PERIOD,
        proportional: float = PROPORTIONAL,
        integral_time: float = INTEGRAL_TIME,
        limit: float = GAIN_LIMIT,
    ) -> None:
        self.period, self.proportional = period, proportional
        self.integral_time, self.limit = integral_time, limit
        self._samples: deque[tuple[float, float]] = deque()
        self._last: float | None = None
        self._full = False  # a sample older than the window has been dropped
        self.integral = 0.0  # I [m/s]
        self.error = 0.0  # e [m/s] over the last full window (0 until one is full)

    def reset(self) -> None:
        """Forget the window and the integral (the ride no longer holds its speed)."""
        self._samples.clear()
        self._last, self._full, self.integral, self.error = None, False, 0.0, 0.0

    @property
    def mean(self) -> float | None:
        """:math:`\\bar v` [m/s], or None before a whole window has been seen."""
        if not self._full:
            return None
        return sum(v for _, v in self._samples) / len(self._samples)

    def observe(self, now: float, speed: float, wanted: float) -> None:
        """Take the board's ``speed`` [m/s] at ``now`` [s] against the command ``wanted``
        [m/s]; once a whole window is seen, integrate its error since the last call."""
        self._samples.append((now, speed))
        while now - self._samples[0][0] > self.period:
            self._samples.popleft()
            self._full = True
        mean, last, self._last = self.mean, self._last, now
        if mean is None or last is None:
            return
        self.error = wanted - mean
        step = self.error * (now - last) / self.integral_time
        self.integral = min(max(self.integral + step, 0.0), self.limit)

    @property
    def gain(self) -> float:
        """:math:`u` [m/s]: the speed a re-push is asked to add beyond its entry's."""
        return min(max(self.proportional * self.error + self.integral, 0.0), self.limit)
