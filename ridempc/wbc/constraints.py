"""Constraints of the whole-body QP, each a block of rows :math:`l \\le C z \\le u`.

Every constraint keeps the same rows (and the same non-zero pattern) at every tick, so the
QP's matrices keep a fixed sparsity pattern: an equality has :math:`l = u`, and a row that
does not apply this tick (the contact rows of a foot in the air) gets
:math:`l = -\\infty, u = +\\infty`. :meth:`Constraint.fill_qp_constraint` writes the block
:math:`(C, l, u)` into its rows of the QP's own matrix and bounds, in place (the tick then
allocates and stacks no blocks); :meth:`Constraint.compute_qp_constraint` returns it alone,
as a :class:`LinearConstraint`. An inequality
:math:`G z \\le h` is :math:`(G, -\\infty, h)` and an equality :math:`A z = b` is
:math:`(A, b, b)`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ridempc.friction import pyramid_matrix
from ridempc.robots.motor_curve import TorqueSpeedCurve
from ridempc.wbc.contacts import ContactSet
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.model import ModelTerms
from ridempc.wbc.platforms import RollingPlatform
from ridempc.wbc.targets import WbcTargets
from ridempc.wheel_grip import WHEEL_GRIP

__all__ = [
    "ClosedChainConstraint",
    "Constraint",
    "ContactAccelerationConstraint",
    "DynamicsConstraint",
    "FrictionPyramidConstraint",
    "LinearConstraint",
    "PlatformTipConstraint",
    "RigidSpringConstraint",
    "TorqueLimitConstraint",
    "TorqueSpeedConstraint",
    "WheelGripConstraint",
]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
INF: float = np.inf
_XYZ = np.arange(3)


class LinearConstraint(NamedTuple):
    """Rows :math:`l \\le C z \\le u`.

    Attributes:
        matrix: :math:`C`, shape (rows, n_z).
        lower: :math:`l` (``-inf`` where unbounded).
        upper: :math:`u` (``+inf`` where unbounded).
    """

    matrix: Array
    lower: Array
    upper: Array


class Constraint(ABC):
    """A block of QP rows with a fixed shape.

    Args:
        layout: The decision vector's layout.

    Attributes:
        rows: Number of rows, the same at every tick.
        soft: Whether its rows may give way, with a slack, when the QP has no solution
            (:mod:`ridempc.wbc.elastic`); the dynamics and the torque limits never do.
    """

    rows: int
    soft: bool = False

    def __init__(self, layout: DecisionLayout) -> None:
        self.layout = layout

    @abstractmethod
    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        """Write the block's :math:`(C, l, u)` into ``block``: its ``matrix`` (rows, n_z)
        holds zeros, its ``lower`` and ``upper`` (rows,) anything; every bound is set."""

    def compute_qp_constraint(
        self, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> LinearConstraint:
        """The block's :math:`(C, l, u)` alone."""
        block = LinearConstraint(
            np.zeros((self.rows, self.layout.size)), np.empty(self.rows), np.empty(self.rows)
        )
        self.fill_qp_constraint(block, terms, targets, contacts)
        return block


class DynamicsConstraint(Constraint):
    """Floating-base dynamics, all :math:`n_v` rows (the six base rows have no torque):

    .. math:: M \\ddot q + h = S^\\top \\tau + J_c^\\top f + J_{loop}^\\top \\lambda + \\tau_p

    [N, N m], with :math:`S^\\top` placing each motor's torque on its joint, :math:`J_c` the
    contact sites' stacked Jacobians, and :math:`\\tau_p` the passive torques (springs and
    damping, see :mod:`ridempc.wbc.model`): a passive joint takes no motor torque.

    The rows of ``free_rows`` are left free (infinite bounds): a spring taken as rigid
    (:class:`RigidSpringConstraint`) exerts whatever torque holds it, so its row says nothing.

    Args:
        layout: The decision vector's layout.
        motor_v: Velocity index of each motor's joint.
        free_rows: Velocity indices whose rows are left free.
    """

    def __init__(
        self, layout: DecisionLayout, motor_v: Index, free_rows: Index | None = None
    ) -> None:
        super().__init__(layout)
        self.rows = layout.nv
        self._motor_entries = (motor_v, layout.torque.start + np.arange(layout.n_motors))
        free = np.zeros(layout.nv, dtype=bool)
        if free_rows is not None:
            free[free_rows] = True
        self._free_rows = np.flatnonzero(free)

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        layout, matrix = self.layout, block.matrix
        matrix[self._motor_entries] = -1.0  # -S^T
        matrix[:, layout.acceleration] = terms.mass_matrix
        np.negative(terms.sites.jacobian.reshape(-1, layout.nv).T, out=matrix[:, layout.force])
        np.negative(terms.loop_jacobian.T, out=matrix[:, layout.loop_force])
        b = terms.passive - terms.bias
        block.lower[:] = block.upper[:] = b
        if self._free_rows.size:
            block.lower[self._free_rows] = -INF
            block.upper[self._free_rows] = INF


class RigidSpringConstraint(Constraint):
    """Leaf springs taken as rigid: each spring joint :math:`s` only has its motion damped,

    .. math:: \\ddot q_s = -k_d \\dot q_s \\quad [rad/s^2],

    and its dynamics row is left free (:class:`DynamicsConstraint`), so the QP neither reads
    the spring's torque from its measured deflection :math:`-k (q_s - q_{ref})` nor lets the
    spring swing.

    Cassie stands in simulation this way and not with passive springs: MuJoCo's achilles-rod
    ``connect`` is soft (``solref`` 0.005 s) and stretches by about 2 mm under the standing
    load, so the heel-spring deflection that the estimator solves from the rigid closure is
    about twice the true one (-0.053 against -0.026 rad once settled, some 33 N m of heel
    torque that is not there). Taking that torque as known, the QP answers it with a pelvis
    pitch acceleration that grows (-50 to -390 rad/s^2 over 0.12 s) until OSQP fails, 0.14 s
    after the start.

    Args:
        layout: The decision vector's layout.
        spring_v: Velocity index of each spring joint.
        damping: :math:`k_d` [1/s].
    """

    soft = True  # a model of a stiff spring, not physics: it may give way

    def __init__(self, layout: DecisionLayout, spring_v: Index, damping: float) -> None:
        super().__init__(layout)
        self.rows = len(spring_v)
        self._spring_v = np.asarray(spring_v, dtype=np.int64)
        self._entries = (np.arange(self.rows), self._spring_v)
        self.damping = damping

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        block.matrix[self._entries] = 1.0
        block.lower[:] = block.upper[:] = -self.damping * terms.v[self._spring_v]


class ClosedChainConstraint(Constraint):
    """Closed chains hold at the acceleration level: :math:`\\ddot r = 0`,

    .. math:: J_{loop} \\ddot q + \\dot J_{loop} v = 0 \\quad [m/s^2].

    Args:
        layout: The decision vector's layout.
    """

    # its drift comes from estimated velocities, which a fall can make contradict the dynamics
    soft = True

    def __init__(self, layout: DecisionLayout) -> None:
        super().__init__(layout)
        self.rows = 3 * layout.n_loops

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        block.matrix[:, self.layout.acceleration] = terms.loop_jacobian
        block.lower[:] = block.upper[:] = -terms.loop_drift


class ContactAccelerationConstraint(Constraint):
    """Sites in contact move with their support: :math:`E_s (J_s \\ddot q + \\dot J_s v) =
    E_s a_s^*` [m/s^2], :math:`a_s^*` from :mod:`ridempc.wbc.contacts`; on a support that the
    forces move, :math:`a_s^* = a_s + \\sum_j K_{sj} f_j`, so the rows read
    :math:`E_s (J_s \\ddot q - \\sum_j K_{sj} f_j) = E_s (a_s - \\dot J_s v)`.

    A foot's first site is held in all three directions (:math:`E_s = I`). A line foot's
    second site is held only across the line joining the two,
    :math:`E_s = B_s R_{WS}^\\top` with :math:`B_s` two unit rows orthogonal to the line in
    the site's frame (``WholeBodyModel.line_basis``): along the line the two points of a
    rigid foot cannot move apart, so that row would repeat the others (and contradict them
    by the rounding of :math:`\\dot J v`). The foot keeps its roll about the line, as a
    capsule does.

    Args:
        layout: The decision vector's layout.
        site_partner: Per site, the first site of its line foot if it is the second, else -1.
        line_basis: Per site, :math:`B_s` (used for the second sites), shape (sites, 2, 3).
    """

    soft = True  # a planned contact may be slipping or lifting already

    def __init__(self, layout: DecisionLayout, site_partner: Index, line_basis: Array) -> None:
        super().__init__(layout)
        first = np.asarray(site_partner) < 0
        self._first = np.flatnonzero(first)
        self._second = np.flatnonzero(~first)
        self._basis = np.asarray(line_basis)[self._second]
        # rows: three per first site, then two per second site
        self._split = 3 * self._first.size
        self.rows = self._split + 2 * self._second.size
        self._row_site = np.concatenate([np.repeat(self._first, 3), np.repeat(self._second, 2)])
        # E, all sites' held directions as rows over their stacked coordinates (rows, 3 n):
        # the first sites' identity blocks are fixed, the second sites' 2 x 3 blocks are
        # written each tick (flat indices, in the order of their (site, row, column))
        n = len(first)
        self._select = np.zeros((self.rows, 3 * n))
        for r, s in enumerate(self._first.tolist()):
            self._select[3 * r : 3 * r + 3, 3 * s : 3 * s + 3] = np.eye(3)
        rows = self._split + 2 * np.arange(self._second.size)[:, None, None] + np.arange(2)[:, None]
        columns = 3 * self._second[:, None, None] + np.arange(3)
        self._second_entries = (rows * 3 * n + columns).ravel()

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        nv, split, select = self.layout.nv, self._split, self._select
        first, second = self._first, self._second
        sites = terms.sites
        wanted = contacts.acceleration - sites.drift
        b = np.empty(self.rows)
        b[:split] = wanted[first].ravel()
        if second.size:
            basis = self._basis @ terms.site_rotation[second].transpose(0, 2, 1)  # E_s, world
            select.put(self._second_entries, basis)
            b[split:] = (basis @ wanted[second][:, :, None]).ravel()
        matrix = block.matrix
        matrix[:, :nv] = select.dot(sites.jacobian.reshape(-1, nv))
        if contacts.coupling is not None:  # a* = a + K f: the forces' part moves left
            n = 3 * len(contacts.active)
            matrix[:, self.layout.force] = -select.dot(contacts.coupling.reshape(n, n))
        active = contacts.active[self._row_site]
        block.lower[:] = np.where(active, b, -INF)
        block.upper[:] = np.where(active, b, INF)


class FrictionPyramidConstraint(Constraint):
    """Unilateral contact inside the friction cone's inner pyramid (slope
    :math:`s = \\mu/\\sqrt2`, :mod:`ridempc.friction`), in each site's support frame:

    .. math:: |t_k^\\top f_s| \\le s\\, n^\\top f_s \\ (k = 1, 2), \\qquad
              f_{min} \\le n^\\top f_s \\le f_{max}

    [N] for a site in contact (the pyramid implies :math:`n^\\top f_s \\ge 0`, so with
    :math:`f_{min} = 0` the normal row only bounds from above; a site's ``least_force`` in the
    :class:`~ridempc.wbc.contacts.ContactSet` raises its :math:`f_{min}`), or in the ``diamond``
    :math:`|t_1^\\top f_s| + |t_2^\\top f_s| \\le \\mu\\, n^\\top f_s`. A site in the air gets
    no force, :math:`f_s = 0`, as three equalities on the same rows (the first and third
    tangent rows and the normal: :math:`(t_1 - s n)^\\top f_s = (t_2 - s n)^\\top f_s =
    n^\\top f_s = 0` in the box, :math:`(t_1 + t_2 - \\mu n)^\\top f_s = (t_2 - t_1 - \\mu
    n)^\\top f_s = n^\\top f_s = 0` in the diamond), the other two left free: pinning all
    five at zero would make a degenerate active set (five rows on three unknowns), on which
    OSQP's polishing fails.

    Args:
        layout: The decision vector's layout.
        friction: Coulomb coefficient :math:`\\mu` [-].
        min_normal_force: :math:`f_{min}` [N].
        max_normal_force: :math:`f_{max}` [N].
        shape: The pyramid's shape (:func:`ridempc.friction.pyramid_rows`).
    """

    soft = True  # a planned contact may not be able to give the force

    def __init__(
        self,
        layout: DecisionLayout,
        friction: float,
        min_normal_force: float,
        max_normal_force: float,
        shape: str = "box",
    ) -> None:
        super().__init__(layout)
        self.friction = friction
        self.min_normal_force = min_normal_force
        self.max_normal_force = max_normal_force
        self.rows = 5 * layout.n_sites
        sites = np.arange(layout.n_sites)
        # (site, row, component) -> row 5 s + row, column of f_s's component
        self._row_index = np.broadcast_to(
            (5 * sites[:, None] + np.arange(5))[:, :, None], (layout.n_sites, 5, 3)
        ).ravel()
        self._column_index = np.broadcast_to(
            (layout.force.start + 3 * sites[:, None] + np.arange(3))[:, None, :],
            (layout.n_sites, 5, 3),
        ).ravel()
        lowest = min_normal_force if min_normal_force > 0.0 else -INF
        self._contact_lower = np.tile([-INF, -INF, -INF, -INF, lowest], layout.n_sites)
        self._contact_upper = np.tile([0.0, 0.0, 0.0, 0.0, max_normal_force], layout.n_sites)
        self._swing_lower = np.tile([0.0, -INF, 0.0, -INF, 0.0], layout.n_sites)
        self._swing_upper = np.tile([0.0, INF, 0.0, INF, 0.0], layout.n_sites)
        self._bounds: dict[bytes, tuple[Array, Array]] = {}  # (lower, upper) per contact pattern
        pyramid = pyramid_matrix(friction, shape)
        # rows t1 - s n, -t1 - s n, t2 - s n, -t2 - s n, n of the frame (t1, t2, n) in the
        # box; t1 + t2 - mu n, t1 - t2 - mu n, t2 - t1 - mu n, -t1 - t2 - mu n, n in the diamond
        self._pyramid = np.vstack([0.0 - pyramid[1:], pyramid[:1]])  # (no negative zeros)

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        rows = self._pyramid @ contacts.frame  # (sites, 5, 3)
        block.matrix[self._row_index, self._column_index] = rows.ravel()
        key = contacts.active.tobytes()
        bounds = self._bounds.get(key)
        if bounds is None:  # a few contact patterns per ride
            active = np.repeat(contacts.active, 5)
            bounds = self._bounds[key] = (
                np.where(active, self._contact_lower, self._swing_lower),
                np.where(active, self._contact_upper, self._swing_upper),
            )
        block.lower[:], block.upper[:] = bounds
        if contacts.least_force is not None:
            normal = 5 * np.arange(self.layout.n_sites) + 4
            bounded = contacts.active & (contacts.least_force > 0.0)
            block.lower[normal] = np.where(
                bounded, np.maximum(block.lower[normal], contacts.least_force), block.lower[normal]
            )


class PlatformTipConstraint(Constraint):
    """A platform on one wheel does not tip over its tread's edges: the centre of pressure
    of its ground contact stays within the tread, :math:`|y_c| \\le w/2`. With the forces
    :math:`f_s` on the robot at the platform's sites, at height :math:`h` over the ground and
    :math:`y_s` across the platform's axis, the moment balance about the axis gives
    :math:`y_c = \\sum_s (y_s\\, n^\\top f_s - h\\, t_2^\\top f_s) / \\sum_s n^\\top f_s`,
    so, per platform, two rows

    .. math:: \\sum_s \\big((\\pm y_s / h - w/2h)\\, n - (\\pm t_2)\\big)^\\top f_s \\le 0

    (:math:`t_2` the platform's sideways axis, :math:`n` its normal, from the contact set;
    the shoe's own weight, which helps, is left out). A Hovershoe's tread is 0.09 m wide
    under a deck 0.11 m high: the feet's net sideways force may be at most 0.41 of their
    load, less than the diamond friction pyramid's 0.6 (:mod:`ridempc.friction`), which a
    line foot needs to twist the shoe (with opposite sideways forces at its ends, which tip
    nothing).

    Args:
        layout: The decision vector's layout.
        platforms: How many platforms tip (rows for each; a platform without sites in a
            tick keeps its rows empty).
    """

    soft = True  # the tread's edge models the platform; not a limit of the robot

    def __init__(self, layout: DecisionLayout, platforms: int) -> None:
        super().__init__(layout)
        self.rows = 2 * platforms
        self._lower = np.full(self.rows, -INF)
        self._upper = np.zeros(self.rows)
        self._entries: dict[tuple[bytes, ...], tuple[Index, Index, Index]] = {}

    def _indices(self, sites: tuple[Index, ...]) -> tuple[Index, Index, Index]:
        """The platforms' sites in a row, and the flat indices (rows ``+`` and ``-``, in the
        block's own matrix) of their three force components; a few distinct lists per ride."""
        key = tuple(s.tobytes() for s in sites)
        cached = self._entries.get(key)
        if cached is None:
            stacked = np.concatenate(sites)
            platform = np.repeat(np.arange(len(sites)), [len(s) for s in sites])
            columns = (self.layout.force.start + 3 * stacked[:, None] + np.arange(3)).ravel()
            plus = np.repeat(2 * platform, 3) * self.layout.size + columns
            cached = self._entries[key] = (stacked, plus, plus + self.layout.size)
        return cached

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        tipping = contacts.tipping[: self.rows // 2]
        if tipping:
            sites, plus, minus = self._indices(tuple(t[0] for t in tipping))
            offsets = np.concatenate([t[1] for t in tipping])[:, None]
            ratio = np.concatenate([t[2] for t in tipping])[:, None]
            axes = contacts.frame[sites]
            side, normal = axes[:, 1], axes[:, 2]
            block.matrix.put(plus, (offsets - ratio) * normal - side)
            block.matrix.put(minus, (-offsets - ratio) * normal + side)
        block.lower[:] = self._lower
        block.upper[:] = self._upper


class WheelGripConstraint(Constraint):
    """A platform on one wheel neither skids sideways nor spins on the floor
    (:mod:`ridempc.wheel_grip`): per platform that tips (the platforms and sites of
    :class:`PlatformTipConstraint`, with the forces :math:`f_s` on the robot at its sites
    :math:`p_s`, the platform's sideways axis :math:`t_2` and normal :math:`n`), four rows

    .. math::

        \\pm \\sum_s t_2^\\top f_s - \\mu_g \\sum_s n^\\top f_s \\le 0, \\qquad
        \\pm \\frac{2}{w} M - \\mu_g \\sum_s n^\\top f_s \\le \\frac{2}{w} c_3 |\\omega_z|,
        \\qquad M = -\\sum_s f_s^\\top \\big(n \\times (p_s - \\bar p)\\big):

    the feet's net sideways force within :math:`\\mu_g` of their load, and their twist
    :math:`M` [N m] on the shoe (about its feet's centroid :math:`\\bar p`, where the
    estimate puts the platform) within what the tyre's two rims, :math:`w/2` either side of
    its middle, hold by friction, :math:`\\mu_g N w / 2`, plus what the planned turn
    needs: eq. (5)'s rim damping :math:`c_3` at the rider's planned yaw rate
    :math:`\\omega_z` (on a grippier floor a turn slides the rims against more than
    :math:`\\mu_g`). Beyond it the rims slip and the shoe spins: eq. (5)'s linear damping,
    identified on a floor of friction 1, holds 3-5 times the torque the rims of a 0.2-0.3
    floor do, so plans built on it drive the shoes' yaw round at 3-4 Hz. Each row gives
    the whole grip to one of the two (a box, not the rims' shared cone); the foot's own
    offset along the shoe (the shoe observer's :math:`d`, a few cm) is left out of :math:`M`.

    Args:
        layout: The decision vector's layout.
        platforms: The board's rolling platforms; those with a tread get rows, in order.
        grip: :math:`\\mu_g` [-], the wheel's grip on the floor.
    """

    soft = True  # the floor's grip models the board; not a limit of the robot

    def __init__(
        self,
        layout: DecisionLayout,
        platforms: Sequence[RollingPlatform | None],
        grip: float = WHEEL_GRIP,
    ) -> None:
        super().__init__(layout)
        self.grip = grip
        wheels = [p for p in platforms if p is not None and p.tread is not None]
        self._twist = np.array([2.0 / p.tread for p in wheels if p.tread is not None])  # [1/m]
        self._allowance = self._twist * [p.twist_damping for p in wheels]  # 2 c_3 / w [N s]
        self.rows = 4 * len(wheels)
        self._lower = np.full(self.rows, -INF)
        self._upper = np.zeros(self.rows)
        self._entries: dict[tuple[bytes, ...], tuple[Index, Array, Array, Index]] = {}

    def _indices(self, sites: tuple[Index, ...]) -> tuple[Index, Array, Array, Index]:
        """The platforms' sites in a row, each site's 2 / w, the matrix averaging each
        platform's sites, and the flat indices (in the block's own matrix) of the four rows'
        entries per site and force component; a few distinct lists per ride."""
        key = tuple(s.tobytes() for s in sites)
        cached = self._entries.get(key)
        if cached is None:
            stacked = np.concatenate(sites)
            platform = np.repeat(np.arange(len(sites)), [len(s) for s in sites])
            same = platform[:, None] == platform[None, :]
            mean = same / same.sum(axis=1, keepdims=True)
            columns = self.layout.force.start + 3 * stacked[:, None] + _XYZ  # (sites, 3)
            rows = 4 * platform[:, None] + np.arange(4)  # (sites, 4)
            flat = rows[:, :, None] * self.layout.size + columns[:, None, :]  # (sites, 4, 3)
            cached = (stacked, self._twist[platform][:, None], mean, flat.ravel())
            self._entries[key] = cached
        return cached

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        block.lower[:] = self._lower
        block.upper[:] = self._upper
        wheels = contacts.tipping[: self.rows // 4]
        if not wheels:
            return
        sites, twist, mean, flat = self._indices(tuple(t[0] for t in wheels))
        axes = contacts.frame[sites]
        side, normal = axes[:, 1], axes[:, 2]
        place = terms.sites.position[sites]
        lever = place - mean @ place  # from the feet's centroid on each shoe
        # per site its four rows (side, -side, M, -M) less the grip's load, written in place
        # (two np.stack's copies and wrappers were a fifth of this block's time)
        rows = np.empty((len(sites), 4, 3))
        rows[:, 0] = side
        np.negative(side, out=rows[:, 1])
        moment = rows[:, 2]  # M's coefficients, -(2/w) n x l, per site
        moment[:, 0] = normal[:, 2] * lever[:, 1] - normal[:, 1] * lever[:, 2]
        moment[:, 1] = normal[:, 0] * lever[:, 2] - normal[:, 2] * lever[:, 0]
        moment[:, 2] = normal[:, 1] * lever[:, 0] - normal[:, 0] * lever[:, 1]
        moment *= twist
        np.negative(moment, out=rows[:, 3])
        rows -= (self.grip * normal)[:, None]
        block.matrix.put(flat, rows)
        turn = abs(float(targets.angular_velocity[2]))
        block.upper[2 : self.rows : 4] = block.upper[3 : self.rows : 4] = self._allowance * turn


class TorqueLimitConstraint(Constraint):
    """Motor torque limits: :math:`-\\tau_{max} \\le \\tau \\le \\tau_{max}` [N m].

    Args:
        layout: The decision vector's layout.
        limits: :math:`\\tau_{max}` per motor [N m], actuator order.
    """

    def __init__(self, layout: DecisionLayout, limits: Array) -> None:
        super().__init__(layout)
        self.rows = layout.n_motors
        self._entries = (np.arange(self.rows), layout.torque.start + np.arange(self.rows))
        self._limits = np.asarray(limits, dtype=float)

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        block.matrix[self._entries] = 1.0
        block.lower[:] = -self._limits
        block.upper[:] = self._limits


class TorqueSpeedConstraint(TorqueLimitConstraint):
    """Motor torque limits at the motors' speeds:
    :math:`-\\tau_{lim}(\\dot q) \\le \\tau \\le \\tau_{lim}(\\dot q)` [N m], from the
    torque-speed curve the motor drivers apply (:mod:`ridempc.robots.motor_curve`), so the QP
    plans no torque the motors cannot give at their present speed.

    Args:
        layout: The decision vector's layout.
        curve: The motors' torque-speed curves, actuator order.
        motor_v: Each motor joint's index in the velocity vector, actuator order.
    """

    def __init__(self, layout: DecisionLayout, curve: TorqueSpeedCurve, motor_v: Index) -> None:
        super().__init__(layout, curve.peak)
        self._curve = curve
        self._motor_v = np.asarray(motor_v, dtype=np.int64)

    def fill_qp_constraint(
        self, block: LinearConstraint, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        block.matrix[self._entries] = 1.0
        limits = self._curve.limit(terms.v[self._motor_v])
        block.lower[:] = -limits
        block.upper[:] = limits
