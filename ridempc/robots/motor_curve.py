"""Motor torque-speed curves: the joint torque a motor can give at a joint speed.

Each motor gives its peak torque up to a corner speed :math:`\\omega_c`, then less, linearly,
down to none at its no-load speed :math:`\\omega_0`:

.. math:: \\tau_{lim}(\\dot q) = \\tau_{peak} \\, \\mathrm{clip}\\Big(
          \\frac{\\omega_0 - |\\dot q|}{\\omega_0 - \\omega_c}, \\; 0, \\; 1\\Big)

[N m, joint side], with :math:`\\omega_c = f \\, \\omega_0` (``full_torque_fraction``). The
limit depends on the speed's magnitude only, so a torque against the motion (braking) is
limited as much as one along it, and beyond the no-load speed the motor gives no torque at
all. That is the motor model of Agility's simulator for Cassie (cassie-mujoco-sim,
``motor()`` in ``cassiemujoco.c``: :math:`\\tau_{lim} = 2 \\tau_{max} (1 - |\\omega| /
\\omega_{max})` within :math:`[0, \\tau_{max}]`, whatever the command's sign, i.e.
:math:`f = 1/2`). The gear scales torque and speed inversely, so the curve is the same on
the motor side and on the joint side.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ridempc.robots.robot import Motor

__all__ = ["TorqueSpeedCurve"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class TorqueSpeedCurve:
    """The torque-speed curves of a robot's motors, in actuator order.

    Attributes:
        peak: Peak joint torque :math:`\\tau_{peak}` [N m].
        corner_speed: Joint speed :math:`\\omega_c` up to which the peak is available [rad/s].
        no_load_speed: Joint speed :math:`\\omega_0` at which no torque is left [rad/s].
    """

    peak: Array
    corner_speed: Array
    no_load_speed: Array
    # the falling part's slope [N m s / rad], kept so that limit() is four ufuncs
    _fall: Array = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_fall", self.peak / (self.no_load_speed - self.corner_speed))

    @classmethod
    def of(cls, motors: Sequence[Motor]) -> TorqueSpeedCurve:
        """The curves of ``motors`` (their MJCF peak torque and ``robot.toml`` figures)."""
        no_load = np.array([m.speed_limit for m in motors], dtype=float)
        return cls(
            peak=np.array([m.torque_limit for m in motors], dtype=float),
            corner_speed=no_load * np.array([m.full_torque_fraction for m in motors]),
            no_load_speed=no_load,
        )

    def limit(self, speed: Array) -> Array:
        """:math:`\\tau_{lim}` at joint speeds ``speed`` [rad/s], per motor [N m] (>= 0)."""
        falling = (self.no_load_speed - np.abs(speed)) * self._fall
        return np.minimum(self.peak, np.maximum(0.0, falling))

    def clip(self, torque: Array, speed: Array) -> Array:
        """``torque`` [N m] clipped to :math:`\\pm\\tau_{lim}` at ``speed`` [rad/s]."""
        limit = self.limit(speed)
        return np.minimum(np.maximum(torque, -limit), limit)

    def scaled(self, scale: float) -> TorqueSpeedCurve:
        """The same curves with every peak torque times ``scale`` (corner and no-load speeds
        kept)."""
        return TorqueSpeedCurve(self.peak * scale, self.corner_speed, self.no_load_speed)
