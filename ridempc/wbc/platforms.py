"""How a board's platform moves under the rider's feet: the contact sites' acceleration as
an affine function of the forces the rider puts on it.

On the ground, or on a heavy deck, a standing site does not accelerate whatever the foot
pushes (:mod:`ridempc.wbc.contacts`). A Hovershoe is different: it is a 2.7 kg shoe on a
wheel that rolls freely forward, so the foot's horizontal push moves it at once, and the
whole-body QP, taking the shoe for ground, used that push to hold the rider's centre of
mass and drove the shoe away from under the foot (with even forces and a fixed centre of
mass target, both shoes ran off backwards at 3.8 m/s within 0.3 s of the start).

:class:`RollingPlatform` is eq. (8) of the hovershoe paper with the rider's push, as in the
MPC's model (:class:`~ridempc.trajopt.platforms.HovershoesBoard`): along the platform's
heading :math:`e_x` (horizontal, from the estimated yaw [rad]) the bare shoe of mass
:math:`m_s` [kg] takes the firmware's drive :math:`c_4 \\theta` [N] (pitch :math:`\\theta`
[rad], nose down positive) and the rider's push :math:`P = -e_x^\\top \\sum_j f_j`, with
:math:`f_j` [N] the platform's force on the rider at each of its sites:

.. math::

    a_i = a_i^0 + \\frac{c_4 \\theta}{m_s} e_x
          - \\frac{1}{m_s} e_x e_x^\\top \\sum_{j \\in P} f_j \\quad [m/s^2]

for every site :math:`i` on the platform; :math:`a_i^0` is the rest of the site's motion
(:mod:`ridempc.wbc.contacts`). Across the heading the tyre holds the shoe (it does not
slide sideways) and the ground carries it vertically, so those directions keep
:math:`a_i^0`. The platform's pitch about its axle is left to the MPC's forces (the QP's
force task): its identified inertia and stiffness include the dead weight they were
identified with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation.state import BoardEstimate

__all__ = ["PlatformResponse", "RollingPlatform"]

Array = NDArray[np.float64]
_ZERO_ROW: tuple[float, float, float] = (0.0, 0.0, 0.0)  # nothing moves the shoe vertically


@dataclass(frozen=True)
class PlatformResponse:
    """Sites' accelerations on one platform, :math:`a = a^0 + K f`.

    Attributes:
        drift: :math:`a^0` added to each site's acceleration [m/s^2], shape (3,).
        coupling: :math:`K_{ij}` [1/kg], the same 3 x 3 block between any two sites of the
            platform (the platform moves as one).
    """

    drift: Array
    coupling: Array


@dataclass(frozen=True)
class RollingPlatform:
    """A self-balancing shoe rolling freely along its heading (module docstring).

    Attributes:
        mass: :math:`m_s` [kg], the bare shoe (platform and wheel).
        drive: :math:`c_4` [N/rad], the firmware's forward force per radian of pitch.
        tread: Width of the wheel's tread on the ground [m], about whose edges the shoe
            tips sideways (None: it does not tip; :class:`~ridempc.wbc.constraints.
            PlatformTipConstraint`).
        height: Height of the deck's top, where the feet stand, over the ground [m].
        twist_damping: :math:`c_3` [N m s/rad], the yaw torque per yaw rate its wheel's rims
            take sliding round on the floor (eq. (5); :class:`~ridempc.wbc.constraints.
            WheelGripConstraint`).
    """

    mass: float
    drive: float
    tread: float | None = None
    height: float = 0.0
    twist_damping: float = 0.0

    def __post_init__(self) -> None:
        if not (self.mass > 0.0 and math.isfinite(self.drive)):
            raise ValueError(f"rolling platform: mass {self.mass} kg, drive {self.drive} N/rad")
        if self.tread is not None and not (self.tread > 0.0 and self.height > 0.0):
            raise ValueError(f"rolling platform: tread {self.tread} m, height {self.height} m")

    def response(self, board: BoardEstimate) -> PlatformResponse:
        """The shoe's response at the estimated pitch and heading."""
        # plain floats: a 3 x 3 block per tick, where NumPy's per-call cost dominates
        c, s, m = math.cos(board.yaw), math.sin(board.yaw), self.mass
        push = self.drive * board.pitch / m
        return PlatformResponse(
            drift=np.array([push * c, push * s, 0.0]),
            coupling=np.array(
                [[-(c * c) / m, -(c * s) / m, 0.0], [-(s * c) / m, -(s * s) / m, 0.0], _ZERO_ROW]
            ),
        )
