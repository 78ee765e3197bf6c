"""The held speed's outer loop: a PI over the re-pushes, on the board's speed over a stroke.

A rider holding a commanded speed :math:`v^*` [m/s] on a board only a push drives pushes
again from the rolling board (the library's ``repush`` entries) once it has slowed. Each
re-push's strokes are laid to add the entry's gain (:data:`~ridempc.mpc.manoeuvre.REPUSH_BAND`)
against rolling resistance; a stroke that falls short of it (a rolled deck in a turn, a
board slower than the entry's rolling start) leaves the board slower, and nothing asked it
back: the speed decayed re-push by re-push.

So an outer loop, the standard cascade over an inner tracking loop, measures the speed the
strokes hold and asks the next re-push for more. It samples once per stride: at each
re-push it takes the board's speed averaged over the stride before (since the last re-push,
or since the coast after the push-off began), :math:`\\bar v_k`, a whole cycle of strokes
and coasts, so the speed a stroke gives and rolling resistance takes off again do not move
it. The re-pushes alone hold the board between :math:`v^*` and :math:`v^* - b`
(``REPUSH_BAND``, :math:`b`: a coast down to the rolling start, a stride back up), about
:math:`v^* - b/2` on average, and the loop asks only for what they miss of that:

.. math:: e_k = v^* - b/2 - \\bar v_k, \\qquad
    I_{k+1} = \\mathrm{clip}(I_k + e_k T_k / T_i, 0, u_{max}), \\qquad
    u_k = \\mathrm{clip}(K_p e_k + I_{k+1}, 0, u_{max}),

with :math:`T_k` the stride's length [s]. :math:`u` [m/s] is the speed a re-push is asked
to add beyond its entry's gain, used twice: a coasting board is pushed again :math:`u`
sooner (at :math:`v^* - b + u`), and the re-push's reference asks for :math:`u` more over
its ground time (:mod:`~ridempc.mpc.push_gain`). The loop runs only while the ride holds
its speed after the push-off (a push-off from rest is not a shortfall), and never asks for
less than the entry: a board faster than the command coasts down to it.
"""

from __future__ import annotations

from ridempc.mpc.manoeuvre import REPUSH_BAND

__all__ = [
    "GAIN_LIMIT",
    "INTEGRAL_TIME",
    "PROPORTIONAL",
    "ROLLING_DECELERATION",
    "STROKE_PERIOD",
    "StrokeSpeedLoop",
]

# [s] one stroke and the swing before it: the library's skate entries lay their strokes at
# this period (the trajopt's ``period`` option of both skateboard pairs)
STROKE_PERIOD: float = 1.2
# [m/s^2] the coasting deceleration of a rider on the deck by rolling resistance (the board
# measured coasting straight, 0.14 m/s^2, docs/tuning.md): what each stroke must replace
ROLLING_DECELERATION: float = 0.14
# [-] a re-push is asked back the shortfall measured over the last stride, all of it: one
# stride of strokes is the loop's sample, as a deadbeat step asks a sample's error back
PROPORTIONAL: float = 1.0
# [s] a persistent shortfall is asked back once more per stroke period: the integral time
# is the strokes' period, the fastest the strokes can give speed back
INTEGRAL_TIME: float = STROKE_PERIOD
# [m/s] the most a re-push is asked beyond its entry: what rolling resistance takes over one
# stroke's period (one stroke's loss replaced twice in a stride of two), 0.17 m/s
GAIN_LIMIT: float = ROLLING_DECELERATION * STROKE_PERIOD


class StrokeSpeedLoop:
    """The PI of the held speed (see the module docstring).

    Args:
        proportional: :math:`K_p` [-].
        integral_time: :math:`T_i` [s].
        limit: :math:`u_{max}` [m/s].
    """

    def __init__(
        self,
        proportional: float = PROPORTIONAL,
        integral_time: float = INTEGRAL_TIME,
        limit: float = GAIN_LIMIT,
    ) -> None:
        self.proportional, self.integral_time, self.limit = proportional, integral_time, limit
        self._begun: float | None = None  # the stride's start [s]
        self._sum = self._count = 0.0  # the board's speeds over it [m/s], how many
        self.integral = 0.0  # I [m/s]
        self.gain = 0.0  # u [m/s]: the speed a re-push is asked to add beyond its entry's

    def reset(self) -> None:
        """Forget the stride and the integral (the ride no longer holds its speed)."""
        self._begun, self._sum, self._count = None, 0.0, 0.0
        self.integral = self.gain = 0.0

    @property
    def mean(self) -> float | None:
        """:math:`\\bar v` [m/s] over the stride so far, or None before any speed."""
        return self._sum / self._count if self._count else None

    def observe(self, now: float, speed: float) -> None:
        """Take the board's ``speed`` [m/s] at ``now`` [s] into the stride's mean."""
        if self._begun is None:
            self._begun = now
        self._sum += speed
        self._count += 1.0

    def stride(self, now: float, wanted: float) -> float:
        """Close the stride at a re-push at ``now`` [s], the command ``wanted`` [m/s]:
        update :math:`I` and :math:`u` from its mean, begin the next; returns :math:`u`."""
        mean, begun = self.mean, self._begun
        if mean is not None and begun is not None and now > begun:
            error = wanted - 0.5 * REPUSH_BAND - mean
            step = error * (now - begun) / self.integral_time
            self.integral = min(max(self.integral + step, 0.0), self.limit)
            self.gain = min(max(self.proportional * error + self.integral, 0.0), self.limit)
        self._begun, self._sum, self._count = now, 0.0, 0.0
        return self.gain
