"""Where each contact site stands this tick: its support's normal, tangents and motion.

A site is *active* when its foot is planned in contact. It then stays on its support:

- on the ground: normal :math:`n = e_z`, tangents :math:`e_x, e_y`, and the point does not
  accelerate, :math:`a^* = 0`;
- on a board platform (its foot listed in a :class:`~ridempc.estimation.BoardEstimate`):
  the platform's axes :math:`R_{WP} = R_z(\\psi) R_y(\\theta) R_x(\\phi)` from the estimate's
  yaw, pitch and roll give :math:`n = R_{WP} e_z` (the tilted deck's normal) and the
  tangents :math:`R_{WP} e_x, R_{WP} e_y`; the point moves with the platform,

  .. math:: a^* = a_P + \\omega_P \\times (\\omega_P \\times r), \\qquad r = p - o_P

  [m/s^2], with :math:`a_P` the platform origin's acceleration (the targets', zero if
  unknown), :math:`\\omega_P = (0, 0, \\dot\\psi)` [rad/s] the estimate's yaw rate (the
  estimator does not report roll and pitch rates) and :math:`o_P` its origin [m]. The
  tangential (Euler) term :math:`\\dot\\omega_P \\times r` is left out: it is not estimated.

  A platform that the rider's own push moves (a Hovershoe, :mod:`ridempc.wbc.platforms`)
  adds its response: :math:`a^* = a^0 + K f`, affine in the forces :math:`f` on the
  platform's sites, so the contact rows of the QP hold forces as well as accelerations.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.estimation.state import BoardEstimate
from ridempc.wbc.model import ModelTerms
from ridempc.wbc.platforms import RollingPlatform

__all__ = ["ContactSet", "build_contact_set", "platform_rotation"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
_AXES = np.eye(3)
_XYZ = np.arange(3)


def platform_rotation(board: BoardEstimate) -> Array:
    """:math:`R_{WP} = R_z(\\psi) R_y(\\theta) R_x(\\phi)` of a board estimate (Pinocchio's
    ``rpyToMatrix``)."""
    return np.asarray(pin.rpy.rpyToMatrix(board.roll, board.pitch, board.yaw))


@dataclass(frozen=True)
class ContactSet:
    """The contact sites at one tick, layout order.

    Attributes:
        active: Whether each site is in contact (its foot planned in contact).
        frame: Each site's support axes as rows :math:`(t_1, t_2, n)` [-], shape
            (sites, 3, 3): two tangents and the normal.
        acceleration: Wanted acceleration of each active site :math:`a^*` [m/s^2],
            shape (sites, 3), where no force moves the support.
        coupling: :math:`K` [1/kg], the part of :math:`a^*` that the forces on the robot
            at the sites add, :math:`a^*_i \\mathrel{+}= \\sum_j K_{ij} f_j`, shape
            (sites, 3, sites, 3); None where every support is rigid.
        tipping: Per platform that tips about its tread's edges, its sites, each site's
            sideways offset from the platform's axis over the deck's height
            :math:`y_s / h` [-], and (at each site) half the tread over the height
            :math:`w / 2h` [-] (:class:`~ridempc.wbc.constraints.PlatformTipConstraint`).
        least_force: Each active site's least normal force [N] this tick, over the
            settings' (:class:`~ridempc.wbc.in_flight.TorquesInFlight`); None: the settings'.
    """

    active: NDArray[np.bool_]
    frame: Array
    acceleration: Array
    coupling: Array | None = None
    tipping: tuple[tuple[Index, Array, Array], ...] = ()
    least_force: Array | None = None

    @property
    def normal(self) -> Array:
        """Support normal at each site, shape (sites, 3)."""
        return self.frame[:, 2]

    @property
    def tangents(self) -> Array:
        """Two support tangents at each site, shape (sites, 2, 3)."""
        return self.frame[:, :2]

    @classmethod
    def on_ground(cls, active: NDArray[np.bool_]) -> ContactSet:
        """Every site on flat, still ground."""
        n = len(active)
        return cls(np.asarray(active, dtype=bool), np.tile(_AXES, (n, 1, 1)), np.zeros((n, 3)))


_SITES_ON: dict[tuple[bytes, tuple[str, ...], tuple[str, ...]], Index] = {}
_BLOCKS: dict[tuple[bytes, int], tuple[Index, Index]] = {}


def _sites_on(site_foot: Index, foot_names: tuple[str, ...], feet: tuple[str, ...]) -> Index:
    """The sites of the feet named ``feet`` (a board's), layout order; few distinct calls."""
    key = (site_foot.tobytes(), foot_names, feet)
    sites = _SITES_ON.get(key)
    if sites is None:
        on = [i for i, name in enumerate(foot_names) if name in feet]
        sites = _SITES_ON[key] = np.flatnonzero(np.isin(site_foot, on))
    return sites


def _block_entries(sites: Index, n: int) -> tuple[Index, Index]:
    """Flat indices, into a (n, 3, n, 3) coupling, of the blocks between ``sites``, in
    (site, row, site, column) order, and of the 3 x 3 block's entry that each one takes."""
    key = (sites.tobytes(), n)
    entries = _BLOCKS.get(key)
    if entries is None:
        into = np.ravel_multi_index(np.ix_(sites, _XYZ, sites, _XYZ), (n, 3, n, 3)).ravel()
        taken = np.tile(np.arange(9).reshape(3, 3), (sites.size, sites.size)).ravel()
        entries = _BLOCKS[key] = (into, taken)
    return entries


def build_contact_set(
    terms: ModelTerms,
    site_foot: Index,
    foot_names: Sequence[str],
    contact: NDArray[np.bool_],
    boards: Sequence[BoardEstimate] = (),
    board_acceleration: Sequence[Array] = (),
    platforms: Sequence[RollingPlatform | None] = (),
) -> ContactSet:
    """Normals, tangents and wanted accelerations of the contact sites.

    Args:
        terms: The model at this tick (site positions).
        site_foot: Foot index of each site.
        foot_names: The feet's names.
        contact: Planned contact per foot.
        boards: The estimator's board platforms (empty on the ground).
        board_acceleration: Acceleration of each platform's origin [m/s^2] (zero if missing).
        platforms: Per board, how the rider's forces move it (None or missing: they do not).
    """
    site_foot = np.asarray(site_foot)
    names = tuple(foot_names)
    active = np.asarray(contact, dtype=bool)[site_foot]
    n = len(site_foot)
    frame = _AXES[None].repeat(n, axis=0)
    acceleration = np.zeros((n, 3))
    coupling: Array | None = None
    tipping: list[tuple[Index, Array, Array]] = []
    for k, board in enumerate(boards):
        sites = _sites_on(site_foot, names, board.feet)
        if sites.size == 0:
            continue
        rotation = platform_rotation(board)
        frame[sites] = rotation.T
        lever = terms.sites.position[sites] - board.position
        centripetal = -(board.yaw_rate**2) * lever  # omega x (omega x r), omega along z
        centripetal[:, 2] = 0.0
        if k < len(board_acceleration):
            centripetal += board_acceleration[k]
        platform = platforms[k] if k < len(platforms) else None
        if platform is not None:
            response = platform.response(board)
            centripetal += response.drift
            if coupling is None:
                coupling = np.zeros((n, 3, n, 3))
            into, taken = _block_entries(sites, n)
            coupling.ravel()[into] = response.coupling.ravel()[taken]
            if platform.tread is not None:
                offsets = lever.dot(rotation[:, 1]) / platform.height  # y_s / h
                ratio = np.full(len(sites), 0.5 * platform.tread / platform.height)
                tipping.append((sites, offsets, ratio))
        acceleration[sites] = centripetal
    return ContactSet(active, frame, acceleration, coupling, tuple(tipping))
