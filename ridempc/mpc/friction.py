"""Contact constraints of the MPC: friction pyramids in each contact's surface frame.

For a contact :math:`i` touching a surface of rotation :math:`R_i` (the deck or platform
under it, or the ground's identity), the force on the robot in the surface frame,
:math:`\\phi_i = R_i^\\top f_i` [N], satisfies

.. math::

    f_{min} \\le \\phi_{i,z} \\le f_{max}, \\qquad
    |\\phi_{i,x}| \\le s\\, \\phi_{i,z}, \\qquad |\\phi_{i,y}| \\le s\\, \\phi_{i,z}

with :math:`s = \\mu/\\sqrt2` the slope of the Coulomb cone's inner pyramid
(:mod:`ridempc.friction`: the outer one, :math:`s = \\mu`, let the dog's pushing foot slide)
and :math:`f_{min}` the library's least force on a contact standing on a board (0 on the
ground); five rows :math:`g^{lo} \\le G u \\le g^{hi}` per contact and step. A swinging contact gets
:math:`f_{max} = 0`, so the same rows pin its force to zero: every step has the same rows
with the same sparsity, whatever the contact schedule, which is what lets the QP keep one
pattern. As in the paper (Sec. V-B), the rotations are those of the estimated state, held
over the horizon.

A platform on one wheel (a Hovershoe) also must not tip over its tread's edges: with its
contacts' forces, their sideways axis :math:`t_{2,i}` and normal :math:`n_i`, two rows per
platform and step,

.. math:: \\sum_{i \\in P} (\\pm t_{2,i} - k\\, n_i)^\\top f_i \\le 0, \\qquad k = w / 2h

(tread :math:`w`, deck height :math:`h`; the feet on the platform's axis, its own weight left
out: :class:`~ridempc.wbc.constraints.PlatformTipConstraint` for the whole-body QP's). Nor may
its wheel skid sideways on the floor (:mod:`ridempc.wheel_grip`): the same net sideways force
within :math:`\\mu_g` of the load, rows of the same form, so the two rows carry the lesser
ratio, :math:`k = \\min(w / 2h, \\mu_g)`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ridempc.friction import pyramid_matrix
from ridempc.trajopt.schedule import Contact
from ridempc.wheel_grip import WHEEL_GRIP

__all__ = ["ROWS_PER_CONTACT", "force_bounds", "friction_pyramids", "pyramid_pattern"]

Array = NDArray[np.float64]
Tipping = Sequence[tuple[Sequence[int], float]]  # per platform: its contacts, w / 2h
ROWS_PER_CONTACT = 5


def pyramid_pattern(
    force_index: NDArray[np.int64], nu: int, tipping: Tipping = ()
) -> NDArray[np.bool_]:
    """Where :func:`friction_pyramids`' rows have entries (rows x nu)."""
    nc = len(force_index)
    pattern = np.zeros((ROWS_PER_CONTACT * nc + 2 * len(tipping), nu), dtype=bool)
    for i, columns in enumerate(force_index):
        pattern[ROWS_PER_CONTACT * i : ROWS_PER_CONTACT * (i + 1), columns] = True
    for j, (contacts, _) in enumerate(tipping):
        row = ROWS_PER_CONTACT * nc + 2 * j
        pattern[row : row + 2, np.asarray(force_index)[list(contacts)].ravel()] = True
    return pattern


def friction_pyramids(
    force_index: NDArray[np.int64],
    nu: int,
    schedule: Sequence[Sequence[Contact]],
    surfaces: Array,
    friction: float,
    max_force: float,
    min_force: float = 0.0,
    shape: str = "box",
    tipping: Tipping = (),
    grip: float = WHEEL_GRIP,
) -> tuple[Array, Array, Array]:
    """Friction pyramids of every step (see the module docstring).

    Args:
        force_index: Per contact, the input indices of its force (x, y, z), n_c x 3.
        nu: Input size.
        schedule: Per step, per contact, where it is (board, ground or swing), N x n_c.
        surfaces: Per contact, the rotation of the board surface under it (world from
            surface), n_c x 3 x 3; a contact on the ground uses the identity.
        friction: Coulomb coefficient :math:`\\mu` [-].
        max_force: :math:`f_{max}` [N].
        min_force: :math:`f_{min}` [N] of a contact on a board.
        shape: The pyramid's shape (:func:`ridempc.friction.pyramid_rows`).
        tipping: Per platform that tips, its contacts and :math:`k = w / 2h` [-].
        grip: :math:`\\mu_g` [-], the sideways grip of a tipping platform's wheel on the floor.

    Returns:
        :math:`G` (N x m x nu), :math:`g^{lo}`, :math:`g^{hi}` (N x m), m = 5 n_c plus two
        per tipping platform.
    """
    n, nc = len(schedule), len(force_index)
    rows = ROWS_PER_CONTACT * nc + 2 * len(tipping)
    matrix = np.zeros((n, rows, nu))
    lower = np.full((n, rows), -np.inf)
    upper = np.zeros((n, rows))
    # rows on phi: (phi_z, phi_x - s phi_z, ...), the tangent rows <= 0 (0.0 - x: no -0.0)
    local = pyramid_matrix(friction, shape)
    local[1:] = 0.0 - local[1:]
    kinds = np.array([[kind.value for kind in step] for step in schedule]).reshape(n, nc)
    on_board = kinds == Contact.BOARD.value
    standing = kinds != Contact.SWING.value
    for i in range(nc):
        block = slice(ROWS_PER_CONTACT * i, ROWS_PER_CONTACT * (i + 1))
        board_rows = local @ np.asarray(surfaces[i]).T  # a^T R^T f
        rows_i = np.where(on_board[:, i, None, None], board_rows, local)  # N x 5 x 3
        matrix[:, block, force_index[i]] = rows_i
        lower[:, block.start] = np.where(on_board[:, i], min_force, 0.0)
        upper[:, block.start] = np.where(standing[:, i], max_force, 0.0)
    for j, (contacts, tip) in enumerate(tipping):
        row = ROWS_PER_CONTACT * nc + 2 * j
        ratio = min(tip, grip)  # whichever gives first: the tread's edge or the wheel's grip
        for i in contacts:
            rotation = np.asarray(surfaces[i])  # world from surface: columns t1, t2, n
            side, normal = rotation[:, 1], rotation[:, 2]
            matrix[:, row, force_index[i]] = side - ratio * normal
            matrix[:, row + 1, force_index[i]] = -side - ratio * normal
    return matrix, lower, upper


def force_bounds(
    force_index: NDArray[np.int64],
    schedule: Sequence[Sequence[Contact]],
    limits: Array,
) -> tuple[Array, Array]:
    """Box bounds of the inputs per step: ``limits`` (nu, symmetric, inf for none), and zero
    force on a swinging contact.

    Returns:
        :math:`u^{lo}`, :math:`u^{hi}` (N x nu).
    """
    upper = np.tile(np.asarray(limits, dtype=float), (len(schedule), 1))
    for k, contacts in enumerate(schedule):
        for i, kind in enumerate(contacts):
            if kind is Contact.SWING:
                upper[k, force_index[i]] = 0.0
    return -upper, upper
