"""A drop under the rider: every foot's load gone at once, read from its contact detector.

Rolling off a step, the rider's platforms fall away from under her feet before she follows
them: the feet's loads (:class:`~ridempc.estimation.contact.ContactDetector`, the part of
her weight each foot carries as a fraction of its standing share) fall together. The MPC's
model has no flight phase, so its plans keep pressing the feet against platforms that are
not there (on the Hovershoes: the shoes pushed down at up to 3 g, pitched nose down, and
landing on wheels that their firmware spun up in the air), and the ride is handed to the
backup law (:mod:`ridempc.mpc.handover`), which has a flight phase of its own. A foot
lifted on purpose (a skateboard's pushing foot) leaves the others loaded, so it is no drop.
The loads alone are the rider's vertical acceleration, :math:`\\sum_i \\ell_i \\propto g +
\\ddot z`, and a bounce's top unloads every foot as much as a drop does; what tells them apart is
the way she moves: unloaded while rising, her legs are letting her decelerate (the top of a
bounce); unloaded while sinking, her support is giving way. Sooner than her loads, her feet
say it: held on by the plan's forces, the feet first follow the falling platforms down, and
every foot sinking faster than ``SINK_SPEED`` is a drop too.

.. math:: \\text{drop} \\iff \\big(\\max_i \\ell_i / \\bar\\ell < \\ell_{drop}
          \\wedge \\dot z_{base} \\le 0\\big) \\vee \\max_i \\dot z_i < -v_{sink}
          \\text{ for } n_{drop} \\text{ ticks in a row}

with :math:`\\bar\\ell` the mean load per foot while standing (low-passed over
``STANDING_TICKS``): the loads are fractions of the *modelled* rider's share, and a lighter
rider (a payload of -30 %) stands at 0.7 of it, where a push's sway would read as a drop.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["ARM_TICKS", "DROP_LOAD", "DROP_TICKS", "SINK_SPEED", "STANDING_TICKS", "DropDetector"]

# [-] every foot's load below this share of its standing load: riding, the loads sit at
# 0.9-1.1 and one foot's swings to 0.7; rolling off a step of 171 % of a Hovershoe's wheel
# radius under the MPC both fall from 1.0 to 0.6 within 0.06 s, before the shoes land.
DROP_LOAD: float = 0.6
# [m/s] every foot sinking faster than this (world, estimated) is its platform falling away:
# three times a ride's sinking down the library's steepest slope (13 deg at 0.5 m/s:
# 0.11 m/s), ten times the feet's fastest over rough ground (0.03 m/s); a shoe rolling off a
# 7.6 cm step under the MPC passes it 45 ms before the feet's loads go.
SINK_SPEED: float = 0.3
# [ticks] in a row, 4 ms at 500 Hz: one tick's low reading (a bump) is no drop.
DROP_TICKS: int = 2
# [ticks] every foot loaded in a row, 0.1 s at 500 Hz, before a drop can be told: the rider
# standing on her platforms (the detector's loads start from a placeholder, and a ride may
# start with the rider settling onto them).
ARM_TICKS: int = 50
# [ticks] the standing load's time constant, 1 s at 500 Hz: longer than a push's sway
# (0.1-0.3 s), so the mean follows the rider's weight, not her shifts between the feet.
STANDING_TICKS: int = 500


class DropDetector:
    """Whether every foot has lost its load at once (a drop), from the feet's loads.

    Args:
        threshold: Load fraction below which a foot is unloaded [-] (``DROP_LOAD``).
        ticks: Ticks in a row for a drop (``DROP_TICKS``).
    """

    def __init__(self, threshold: float = DROP_LOAD, ticks: int = DROP_TICKS) -> None:
        if not 0.0 < threshold < 1.0 or ticks < 1:
            raise ValueError(f"drop: threshold {threshold} (0-1), ticks {ticks} (>= 1)")
        self.threshold = threshold
        self.ticks = ticks
        self._count = 0
        self._loaded = 0
        self._armed = False
        self._standing = 1.0  # [-] the mean load per foot while standing (the model's: 1)

    def reset(self) -> None:
        self._count = 0
        self._loaded = 0
        self._armed = False
        self._standing = 1.0

    def update(
        self, loads: NDArray[np.float64], vertical_velocity: float, feet_sinking: float
    ) -> bool:
        """Take this tick's loads, the rider's vertical velocity and her feet's.

        Args:
            loads: One per foot, fractions of the standing share [-].
            vertical_velocity: The base's world vertical velocity, estimated [m/s].
            feet_sinking: The slowest foot's world vertical velocity, estimated (the
                highest of the feet's) [m/s].

        Returns:
            True while every load has been below the threshold with the rider not rising,
            or every foot sinking faster than ``SINK_SPEED``, for ``ticks`` ticks, once the
            loads have all been above the threshold for ``ARM_TICKS`` (a rider not yet
            standing drops nothing).
        """
        if not np.size(loads):
            return False
        limit = self.threshold * self._standing
        loaded = float(np.min(loads)) >= limit
        self._loaded = self._loaded + 1 if loaded else 0
        self._armed = self._armed or self._loaded >= ARM_TICKS
        unloaded = float(np.max(loads)) < limit
        falling = (unloaded and vertical_velocity <= 0.0) or feet_sinking < -SINK_SPEED
        low = self._armed and falling
        if not (self._armed and unloaded):  # the standing mean learns from loaded ticks only
            self._standing += (float(np.mean(loads)) - self._standing) / STANDING_TICKS
        self._count = self._count + 1 if low else 0
        return self._count >= self.ticks
