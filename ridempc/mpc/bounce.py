"""A bounce's way down told from support giving way, by the speed the rider last rose at.

The feet's loads are the rider's vertical acceleration, :math:`\\sum_i \\ell_i \\propto g +
\\ddot z`: past the top of a bounce (the MPC's takeover presses her up at 0.1-0.2 m/s, a
heavy payload more) every foot is as unloaded as when her platforms fall away, and her base
has started to sink (:mod:`~ridempc.mpc.drop`). A bounce is a spring's swing: from its top
she falls back to the height she rose from, where her legs catch her again, reaching there
about the speed she rose at; until then, sinking slower than that, she is on her bounce's
way down, not falling off her support. A platform falling away under a rider who was not
bouncing passes any such speed within a few milliseconds (free fall gains 0.1 m/s in 10 ms).

.. math:: \\dot z_{bounce} = \\dot z + \\dot z^{+}, \\qquad
          \\dot z^{+} = \\max \\dot z \\text{ over the last rise, cleared once }
          \\dot z \\le -\\dot z^{+}

:math:`\\dot z_{bounce} \\le 0` is sinking beyond the bounce's return: what the drop's
detector reads as the rider not rising.
"""

from __future__ import annotations

__all__ = ["BounceRise"]


class BounceRise:
    """The base's vertical velocity less the bounce's return (the module's
    :math:`\\dot z_{bounce}`), from each tick's estimate."""

    def __init__(self) -> None:
        self.rise = 0.0  # [m/s] the fastest the base rose in its last rise (0: none pending)
        self._rising = False

    def reset(self) -> None:
        self.rise, self._rising = 0.0, False

    def update(self, vertical_velocity: float) -> float:
        """Take this tick's base vertical velocity [m/s] (world, estimated); returns it
        with the last rise's speed added while she sinks slower than it [m/s]."""
        v = vertical_velocity
        if v > 0.0:
            self.rise = v if not self._rising else max(self.rise, v)
            self._rising = True
            return v
        self._rising = False
        if v <= -self.rise:  # sunk past the speed she rose at: the bounce has returned
            self.rise = 0.0
        return v + self.rise
