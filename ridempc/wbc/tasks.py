"""Weighted tasks of the whole-body QP, each a least-squares term on :math:`z`.

A task wants :math:`J z = b` with weight :math:`W` (diagonal, non-negative) and contributes

.. math:: \\tfrac12 \\|J z - b\\|_W^2 = \\tfrac12 z^\\top H z + c^\\top z + \\text{const},
          \\qquad H = J^\\top W J, \\quad c = -J^\\top W b

to the objective: :meth:`Task.add_qp_objective` adds that :math:`(H, c)` into the QP's own
on the whole decision vector (see :mod:`ridempc.wbc.layout`), in place, only where the task
has entries: a dense :math:`n \\times n` matrix of each of the nine tasks, summed, cost 3 % of
the whole-body tick on Cassie's Hovershoes ride (callgrind, 5.40 -> 5.24 M instructions);
:meth:`Task.compute_qp_objective` returns it alone. Motion tasks ask for an
acceleration :math:`a^* = a_{ff} + k_p e + k_d \\dot e` of a point or frame whose
acceleration is :math:`J_p \\ddot q + \\dot J_p v`, so :math:`J = J_p` on the
:math:`\\ddot q` block and :math:`b = a^* - \\dot J_p v`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.wbc.contacts import ContactSet
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.model import ModelTerms, PointKinematics
from ridempc.wbc.settings import TrackingGains
from ridempc.wbc.targets import WbcTargets

__all__ = [
    "BaseOrientationTask",
    "BasePositionTask",
    "CenterOfMassTask",
    "ContactForceTask",
    "Objective",
    "PostureTask",
    "RegularizationTask",
    "SwingFootTask",
    "Task",
    "TranslationTask",
]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
_EYE3 = np.eye(3)
# Small products by ``.dot``: NumPy 2's ``@`` costs some 2 us more a call at these sizes.
NORMAL_SHARE: float = 0.1  # [-] weight of a site's normal force share, over its tangential


class Objective(NamedTuple):
    """The QP's objective terms :math:`(H, c)` that the tasks add into, in place.

    Attributes:
        hessian: :math:`H`, shape (n_z, n_z).
        gradient: :math:`c`, shape (n_z,).
    """

    hessian: Array
    gradient: Array


class _PatternTerms(NamedTuple):
    """:class:`ContactForceTask`'s terms for one contact pattern.

    Attributes:
        foot_hessian: The foot term's Hessian block on the forces.
        foot_gradient: Its gradient per wanted foot force.
        share: Each site's even share of its foot's wanted force.
        site_weight: :math:`w_s / m^2` per site, zero for a site whose foot is in the air.
        site_hessian: The site term's Hessian block with the MPC's site forces.
        standing_sites: 1 for each force component of a site whose foot stands, else 0.
    """

    foot_hessian: Array
    foot_gradient: Array
    share: Array
    site_weight: Array
    site_hessian: Array
    standing_sites: Array


class Task(ABC):
    """A weighted least-squares term of the QP's objective.

    Args:
        layout: The decision vector's layout.
    """

    def __init__(self, layout: DecisionLayout) -> None:
        self.layout = layout

    @abstractmethod
    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        """Add the task's :math:`(H, c)` into ``out``'s, of shapes (n_z, n_z) and (n_z,)."""

    def compute_qp_objective(
        self, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> tuple[Array, Array]:
        """The task's :math:`(H, c)` alone, of shapes (n_z, n_z) and (n_z,)."""
        n = self.layout.size
        out = Objective(np.zeros((n, n)), np.zeros(n))
        self.add_qp_objective(out, terms, targets, contacts)
        return out.hessian, out.gradient

    def _add_acceleration_objective(
        self, out: Objective, jacobian: Array, b: Array, weight: float
    ) -> None:
        """Add :math:`(H, c)` of :math:`\\tfrac w2\\|J \\ddot q - b\\|^2`."""
        nv = self.layout.nv
        weighted = weight * jacobian.T
        out.hessian[:nv, :nv] += weighted.dot(jacobian)
        out.gradient[:nv] -= weighted.dot(b)


class BaseOrientationTask(Task):
    """Base orientation by a PD on :math:`SO(3)`:

    .. math:: \\alpha^* = \\alpha_{ff} + k_p \\log(R^* R^\\top) + k_d (\\omega^* - \\omega)

    [rad/s^2] in world axes (:math:`\\log` the rotation vector [rad], :math:`\\omega` the base
    angular velocity [rad/s]). Pinocchio's base angular acceleration is in the base frame,
    so the row is :math:`\\ddot q_{3:6} = R^\\top \\alpha^*`.

    Args:
        layout: The decision vector's layout.
        gains: Weight, :math:`k_p` [1/s^2] and :math:`k_d` [1/s].
    """

    def __init__(self, layout: DecisionLayout, gains: TrackingGains) -> None:
        super().__init__(layout)
        self.gains = gains
        self._diagonal = (np.arange(3, 6), np.arange(3, 6))

    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        g = self.gains
        rotation = terms.base_rotation
        # a unit quaternion (WbcTargets normalises it), as floats: unpacking the array
        # itself makes four NumPy scalars
        w, x, y, z = targets.orientation.tolist()
        wanted = pin.Quaternion(w, x, y, z).toRotationMatrix()
        omega = rotation.dot(terms.base_angular_velocity)  # world axes
        alpha = (
            targets.angular_acceleration
            + g.kp * pin.log3(wanted.dot(rotation.T))
            + g.kd * (targets.angular_velocity - omega)
        )
        out.hessian[self._diagonal] += g.weight
        out.gradient[3:6] -= g.weight * rotation.T.dot(alpha)


class TranslationTask(Task):
    """A point's position by a PD:

    .. math:: \\ddot p^* = a_{ff} + k_p (p^* - p) + k_d (\\dot p^* - \\dot p), \\qquad
              J_p \\ddot q = \\ddot p^* - \\dot J_p v

    [m/s^2], with the targets' ``position``, ``velocity`` and ``acceleration``.

    Args:
        layout: The decision vector's layout.
        gains: Weight, :math:`k_p` [1/s^2] and :math:`k_d` [1/s].
    """

    def __init__(self, layout: DecisionLayout, gains: TrackingGains) -> None:
        super().__init__(layout)
        self.gains = gains

    @abstractmethod
    def point(self, terms: ModelTerms) -> PointKinematics:
        """The tracked point's kinematics."""

    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        g = self.gains
        p = self.point(terms)
        wanted = (
            np.asarray(targets.acceleration)
            + g.kp * (np.asarray(targets.position) - p.position)
            + g.kd * (np.asarray(targets.velocity) - p.velocity)
        )
        self._add_acceleration_objective(out, p.jacobian, wanted - p.drift, g.weight)


class CenterOfMassTask(TranslationTask):
    """The centre of mass tracks the MPC's (see :class:`TranslationTask`)."""

    def point(self, terms: ModelTerms) -> PointKinematics:
        return terms.com


class BasePositionTask(TranslationTask):
    """The base origin tracks the MPC's (see :class:`TranslationTask`)."""

    def point(self, terms: ModelTerms) -> PointKinematics:
        return terms.base


class ContactForceTask(Task):
    """Contact forces close to the MPC's, for the feet in contact:

    .. math:: \\frac{w_f}{2 m^2} \\Big\\|\\sum_{s \\in i} f_s - f_i^*\\Big\\|^2
              + \\frac{w_s}{2 m^2} \\sum_{s \\in i} \\Big\\|T_s^{1/2} \\Big(f_s - \\frac{f_i^*}{n_i}
              \\Big)\\Big\\|^2, \\qquad T_s = I - (1 - \\beta)\\, n_s n_s^\\top

    per foot :math:`i` (:math:`n_i` sites, :math:`m` the robot's mass [kg], so both weights
    are per (N/kg)^2, i.e. per unit of whole-body acceleration; :math:`n_s` the site's
    support normal, :math:`\\beta` = ``NORMAL_SHARE``). The first term tracks the MPC's foot
    force. The second shares it evenly between a line foot's sites, the tangential part
    fully and the normal part only lightly, so that the centre of pressure along the foot
    stays the motion tasks' to choose. It gives the QP curvature along the forces that
    change nothing else, such as a line foot's two sites pulling against each other along
    the line, on which OSQP otherwise converges slowly and polishes badly. (Sharing the
    normal forces as strongly held Cassie's centre of pressure at mid-foot and let its
    centre of mass settle 15 mm behind the target; with :math:`\\beta = 0.1`, 2 mm: measured.)

    Args:
        layout: The decision vector's layout.
        site_foot: Foot index of each contact site.
        mass: Robot mass :math:`m` [kg].
        foot_weight: :math:`w_f` [(kg/N)^2].
        site_weight: :math:`w_s` [(kg/N)^2].
    """

    def __init__(
        self,
        layout: DecisionLayout,
        site_foot: Index,
        mass: float,
        foot_weight: float,
        site_weight: float,
    ) -> None:
        super().__init__(layout)
        feet = int(site_foot.max()) + 1 if site_foot.size else 0
        n_sites = len(site_foot)
        counts = np.bincount(site_foot, minlength=feet)
        # total: foot force = sum of its sites' [3 feet x 3 sites]; share: site -> its foot's
        # force over its site count [3 sites x 3 feet]
        total = np.zeros((3 * feet, 3 * n_sites))
        share = np.zeros((3 * n_sites, 3 * feet))
        for s, foot in enumerate(site_foot):
            total[3 * foot : 3 * foot + 3, 3 * s : 3 * s + 3] = np.eye(3)
            share[3 * s : 3 * s + 3, 3 * foot : 3 * foot + 3] = np.eye(3) / counts[foot]
        self._share = share
        self._total = total
        self._foot_weight = foot_weight / mass**2
        self._site_weight = site_weight / mass**2
        self._site_foot = site_foot
        self._site_rows = np.repeat(site_foot, 3)
        self._foot_rows = np.repeat(np.arange(feet), 3)
        # (site, row, column) -> entry of the site's 3 x 3 diagonal block
        block = 3 * np.arange(n_sites)[:, None, None]
        self._block_rows = np.broadcast_to(block + np.arange(3)[:, None], (n_sites, 3, 3)).ravel()
        self._block_cols = np.broadcast_to(block + np.arange(3)[None, :], (n_sites, 3, 3)).ravel()
        self._identity_blocks = np.tile(_EYE3.ravel(), n_sites)
        self._by_contacts: dict[bytes, _PatternTerms] = {}

    def _terms(self, standing: NDArray[np.bool_]) -> _PatternTerms:
        """What depends on the contact pattern alone, made once per pattern."""
        key = standing.tobytes()
        cached = self._by_contacts.get(key)
        if cached is None:
            feet = standing[self._foot_rows].astype(float)
            sites = standing[self._site_rows].astype(float)
            total = self._total * feet[:, None] * sites[None, :]
            share = self._share * sites[:, None] * feet[None, :]
            weight = np.asarray(self._site_weight * standing[self._site_foot], dtype=float)
            site_hessian = np.zeros((3 * len(self._site_foot), 3 * len(self._site_foot)))
            site_hessian[self._block_rows, self._block_cols] = (
                np.repeat(weight, 9) * self._identity_blocks
            )
            cached = _PatternTerms(
                self._foot_weight * (total.T @ total),
                -self._foot_weight * total.T,
                share,
                weight,
                site_hessian,
                np.repeat(standing[self._site_foot].astype(float), 3),
            )
            self._by_contacts[key] = cached
        return cached

    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        standing = np.asarray(targets.contact, dtype=bool)
        pattern = self._terms(standing)
        wanted = np.asarray(targets.forces, dtype=float).ravel()
        if targets.site_forces is None:
            site_hessian = np.zeros_like(pattern.foot_hessian)
            normal = contacts.normal
            tangential = _EYE3 - (1.0 - NORMAL_SHARE) * normal[:, :, None] * normal[:, None, :]
            site_hessian[self._block_rows, self._block_cols] = (
                tangential * pattern.site_weight[:, None, None]
            ).ravel()
            site_wanted = pattern.share.dot(wanted)
        else:
            if targets.site_forces.shape != (len(self._site_foot), 3):
                raise ConfigError(
                    f"WBC targets: field 'site_forces': expected shape "
                    f"({len(self._site_foot)}, 3), got {targets.site_forces.shape}"
                )
            # the MPC's own site forces, normal part included, at the site weight (holding
            # them as strongly as the feet's totals felled Cassie on the Segway at 1.2 s)
            site_hessian = pattern.site_hessian
            site_wanted = targets.site_forces.ravel() * pattern.standing_sites
        forces = self.layout.force
        out.hessian[forces, forces] += pattern.foot_hessian + site_hessian
        out.gradient[forces] += pattern.foot_gradient.dot(wanted) - site_hessian.dot(site_wanted)


class SwingFootTask(Task):
    """Feet in the air follow their swing targets (push-off):

    .. math:: \\ddot p_i^* = a_{ff} + k_p (p_i^* - p_i) + k_d (\\dot p_i^* - \\dot p_i)

    [m/s^2] for the foot's point (the mean of its contact sites, so
    :math:`J_i = \\frac1{n_i}\\sum_{s \\in i} J_s`), for every foot not in contact when the
    targets carry ``swing_position``.

    Args:
        layout: The decision vector's layout.
        site_foot: Foot index of each contact site.
        gains: Weight, :math:`k_p` [1/s^2] and :math:`k_d` [1/s].
    """

    def __init__(self, layout: DecisionLayout, site_foot: Index, gains: TrackingGains) -> None:
        super().__init__(layout)
        self.gains = gains
        feet = int(site_foot.max()) + 1 if site_foot.size else 0
        counts = np.bincount(site_foot, minlength=feet)
        self._mean = np.zeros((feet, len(site_foot)))  # sites -> foot points
        self._mean[site_foot, np.arange(len(site_foot))] = 1.0 / counts[site_foot]

    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        if targets.swing_position is None:
            return
        swinging = ~np.asarray(targets.contact, dtype=bool)
        if not swinging.any():  # the method: np.any's wrapper costs some 3 us
            return
        g = self.gains
        feet = np.flatnonzero(swinging)
        mean = self._mean[feet]
        sites = terms.sites
        position = mean.dot(sites.position)
        velocity = mean.dot(sites.velocity)
        drift = mean.dot(sites.drift)
        # tensordot's own product, without its wrapper (some 15 us): (feet, sites) by
        # (sites, 3 nv)
        jacobian = mean.dot(sites.jacobian.reshape(len(sites.jacobian), -1))
        jacobian = jacobian.reshape(3 * len(feet), -1)
        zero = np.zeros((len(feet), 3))
        wanted_velocity = zero if targets.swing_velocity is None else targets.swing_velocity[feet]
        feedforward = (
            zero if targets.swing_acceleration is None else targets.swing_acceleration[feet]
        )
        wanted = (
            feedforward
            + g.kp * (targets.swing_position[feet] - position)
            + g.kd * (wanted_velocity - velocity)
        )
        self._add_acceleration_objective(out, jacobian, (wanted - drift).ravel(), g.weight)


class PostureTask(Task):
    """Motor joints towards a nominal posture:
    :math:`\\ddot q_j^* = k_p (q_j^* - q_j) - k_d \\dot q_j` [rad/s^2].

    Args:
        layout: The decision vector's layout.
        motor_q: Configuration index of each motor's joint.
        motor_v: Velocity index of each motor's joint.
        nominal: Default posture, motor joint angles [rad] (the targets' ``posture``
            replaces it when given).
        gains: Weight, :math:`k_p` [1/s^2] and :math:`k_d` [1/s].
    """

    def __init__(
        self,
        layout: DecisionLayout,
        motor_q: Index,
        motor_v: Index,
        nominal: Array,
        gains: TrackingGains,
    ) -> None:
        super().__init__(layout)
        self.motor_q = motor_q
        self.motor_v = motor_v
        self.nominal = np.asarray(nominal, dtype=float)
        self.gains = gains

    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        g = self.gains
        nominal = self.nominal if targets.posture is None else np.asarray(targets.posture)
        wanted = g.kp * (nominal - terms.q[self.motor_q]) - g.kd * terms.v[self.motor_v]
        out.hessian[self.motor_v, self.motor_v] += g.weight
        out.gradient[self.motor_v] -= g.weight * wanted


class RegularizationTask(Task):
    """Small weights on every variable, so the QP is strictly convex:
    :math:`\\tfrac12 (\\epsilon_a \\|\\ddot q\\|^2 + \\epsilon_f \\|f\\|^2 +
    \\epsilon_\\tau \\|\\tau\\|^2 + \\epsilon_\\lambda \\|\\lambda\\|^2)`.

    Args:
        layout: The decision vector's layout.
        acceleration: :math:`\\epsilon_a`.
        force: :math:`\\epsilon_f` [1/N^2].
        torque: :math:`\\epsilon_\\tau` [1/(N m)^2].
        loop_force: :math:`\\epsilon_\\lambda` [1/N^2].
    """

    def __init__(
        self,
        layout: DecisionLayout,
        acceleration: float,
        force: float,
        torque: float,
        loop_force: float,
    ) -> None:
        super().__init__(layout)
        diagonal = np.zeros(layout.size)
        diagonal[layout.acceleration] = acceleration
        diagonal[layout.force] = force
        diagonal[layout.torque] = torque
        diagonal[layout.loop_force] = loop_force
        self._diagonal = diagonal
        self._diagonal_index = np.diag_indices(layout.size)

    def add_qp_objective(
        self, out: Objective, terms: ModelTerms, targets: WbcTargets, contacts: ContactSet
    ) -> None:
        out.hessian[self._diagonal_index] += self._diagonal
