"""The wave pattern for the MPC rider: each platform's reference line moved out sideways.

The command's ``lateral_offset`` is the change of each foot's distance from the centre line
(the Hovershoes paper's :math:`y_{offset}` about its nominal value). The PD baseline takes
it by hip roll and hip yaw; the MPC rider stands on platforms that roll only along their
heading, so here the reference of each platform's position is moved by the offset along
the normal to its reference heading, away from the platforms' mean:

.. math:: p_i^* \\leftarrow p_i^* + \\Delta y \\, \\operatorname{sign}(n_i^\\top (p_i^* -
    \\bar p^*)) \\, n_i, \\qquad n_i = (-\\sin\\psi_i^*, \\cos\\psi_i^*)

and the guidance law (:mod:`ridempc.mpc.guidance`) steers each platform onto its moved line.
The rider also moves the reference it lays the library frame by: that frame follows
platform 0 sideways onto its reference line, and onto the unspread line it followed the
platform out and out (the rider drifted 7-10 cm over 2 s, to the side of platform 0). So the
spread is carried by the platforms other than the one the frame follows, and the rider's
centre moves by the offset towards them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["spread_lines"]

Array = NDArray[np.float64]


def spread_lines(states: Array, columns: Sequence[Sequence[int]], offset: float) -> Array:
    """A copy of the MPC's reference ``states`` (nodes x nx) with each platform's position
    moved ``offset`` [m] further from the platforms' mean, across its heading.

    Args:
        states: The reference over the horizon.
        columns: Each platform's (x, y, heading, ...) state indices.
        offset: Each foot's lateral offset [m] (positive: the feet further apart).
    """
    out = np.array(states, dtype=float)
    if offset == 0.0 or len(columns) < 2:
        return out
    xy = np.stack([out[:, [x, y]] for x, y, *_ in columns])  # platforms x nodes x 2
    mean = xy.mean(axis=0)
    for (x, y, heading, *_), place in zip(columns, xy, strict=True):
        normal = np.column_stack([-np.sin(out[:, heading]), np.cos(out[:, heading])])
        side = np.sign(np.sum(normal * (place - mean), axis=1))
        out[:, x] += offset * side * normal[:, 0]
        out[:, y] += offset * side * normal[:, 1]
    return out
