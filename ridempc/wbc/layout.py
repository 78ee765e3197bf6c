"""The whole-body QP's decision vector and where each of its parts lives.

.. math:: z = (\\ddot q,\\ f,\\ \\tau,\\ \\lambda) \\in
          \\mathbb{R}^{n_v + 3 n_c + n_u + 3 n_l}

- :math:`\\ddot q` [m/s^2, rad/s^2]: generalised acceleration in Pinocchio's coordinates
  (base linear and angular acceleration in the base frame, then the joints);
- :math:`f` [N]: the support's force on each contact point (site), world axes, three per
  point, in ``robot.params.contact_sites`` order grouped by foot;
- :math:`\\tau` [N m]: joint-side motor torques, actuator order;
- :math:`\\lambda` [N]: the force of each closed-chain point constraint (MJCF ``connect``)
  on its first anchor, world axes (the second anchor takes :math:`-\\lambda`); empty for a
  pure tree.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["DecisionLayout"]


@dataclass(frozen=True)
class DecisionLayout:
    """Sizes and slices of the decision vector :math:`z`.

    Attributes:
        nv: Generalised velocity size.
        n_sites: Contact points (three force components each).
        n_motors: Motors (one torque each).
        n_loops: Closed-chain point constraints (three force components each).
    """

    nv: int
    n_sites: int
    n_motors: int
    n_loops: int = 0

    @property
    def size(self) -> int:
        """Length of :math:`z`."""
        return self.nv + 3 * self.n_sites + self.n_motors + 3 * self.n_loops

    @property
    def acceleration(self) -> slice:
        """:math:`\\ddot q` in :math:`z`."""
        return slice(0, self.nv)

    @property
    def force(self) -> slice:
        """:math:`f` in :math:`z` (site-major: :math:`f_{s,x}, f_{s,y}, f_{s,z}`, ...)."""
        return slice(self.nv, self.nv + 3 * self.n_sites)

    @property
    def torque(self) -> slice:
        """:math:`\\tau` in :math:`z`."""
        start = self.nv + 3 * self.n_sites
        return slice(start, start + self.n_motors)

    @property
    def loop_force(self) -> slice:
        """:math:`\\lambda` in :math:`z`."""
        start = self.nv + 3 * self.n_sites + self.n_motors
        return slice(start, start + 3 * self.n_loops)

    def site_force(self, site: int) -> slice:
        """The three force components of contact point ``site`` in :math:`z`."""
        start = self.nv + 3 * site
        return slice(start, start + 3)
