"""A shoe in the air, read from its leg's load: the hovershoe rider's flight detector.

Rolling off a step, a shoe drops away from its foot's load before the rider follows. The
leg's load is measured by Cassie's shin spring (an encoded leaf spring between knee and
shin, :math:`q_{shin} < 0` under load): standing on the shoes it is deflected by about
0.04 rad, and it relaxes to zero when the foot carries nothing. A foot whose shin spring
is deflected by less than ``unloaded_shin`` is **unloaded**: what the kinematics say
about the CoM over that foot (feet at rest) is then wrong, and a toe torque only spins
the light shoe about its axle.

While a foot is unloaded, :class:`~ridempc.baselines.cassie_hovershoes.CassieHovershoes`

- turns its ankle (toe motor, no torque fed forward) to keep the foot at the pitch in the
  world it had when last loaded (from the IMU and the leg's kinematics), so the shoe keeps
  its pitch through the flight and lands as it left, and
- holds the CoM's position and velocity over the feet that the centre-of-pressure law
  reads at their last loaded values (the falling feet are not the rider tipping back), and
- lengthens its leg at ``extend_speed`` (up to ``max_extension``) so that the foot follows
  its falling shoe down; loaded again, the leg shortens back at the posture's slew rate.
  A leg held at its length instead lets the rider fall the whole step onto the shoes
  (1.1 m/s down a 7.6 cm step): the legs then take the landing 13 cm deep at two to three
  times the rider's weight, whose lever about each axle pitches the shoe nose up and its
  firmware brakes it to a stop under a rider still rolling on.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["unloaded_feet"]

Array = NDArray[np.float64]


def unloaded_feet(shin_deflection: Array, unloaded_shin: float) -> NDArray[np.bool_]:
    """Which feet carry (almost) no load, from the shin springs' deflection.

    .. math:: \\text{unloaded}_i = q_{shin,i} > -q_{shin}^{unloaded}

    Args:
        shin_deflection: Shin spring angle per leg (left, right) [rad], negative under load.
        unloaded_shin: Deflection below which a leg is taken as unloaded [rad] (> 0).

    Returns:
        A boolean per leg (left, right).
    """
    return np.asarray(shin_deflection, dtype=float) > -unloaded_shin
