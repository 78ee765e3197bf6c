"""Standard gravity: the one value of g that every model of the package uses.

MuJoCo's default ``opt.gravity`` is (0, 0, -9.81) m/s^2 and no robot or board description
overrides it, so the controllers' models, the papers' laws (eq. 21 of the Hovershoes paper
prints 9.81) and the simulator agree; ``tests/test_gravity.py`` checks every scene against it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["GRAVITY", "GRAVITY_WORLD"]

GRAVITY: float = 9.81  # [m/s^2] magnitude, MuJoCo's default |opt.gravity|
GRAVITY_WORLD: NDArray[np.float64] = np.array([0.0, 0.0, -GRAVITY])  # [m/s^2] world frame, z up
GRAVITY_WORLD.flags.writeable = False  # shared by every importer: never changed in place
