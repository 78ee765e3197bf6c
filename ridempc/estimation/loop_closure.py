"""Unmeasured joints of a closed chain, solved from its loop closure.

Cassie's achilles rod (a ball joint) and heel spring close a four-bar with the knee,
shin and tarsus; only the latter carry encoders. Each closure is a point constraint (an
MJCF ``connect``) between a point :math:`a_1` on joint :math:`j_1` and a point :math:`a_2`
on joint :math:`j_2`:

.. math::

    r(q) = p_{a_1}(q) - p_{a_2}(q) = 0 \\quad [m], \\qquad
    J(q) = \\frac{\\partial r}{\\partial q} = J_{a_1} - J_{a_2} \\quad [m / rad],

with :math:`J_a` the linear part of the world-aligned Jacobian of a frame placed at the
anchor (Pinocchio: :math:`J_{j,lin} - [p_a - p_j]_\\times J_{j,ang}` for joint :math:`j`
carrying it). Splitting the
columns into measured (m) and unmeasured (u) coordinates, the unmeasured configuration
solves :math:`r = 0` by damped Gauss-Newton (minimum-norm steps, so a rod's free twist
about its own axis stays where it was),

.. math::

    \\delta q_u = -J_u^\\top (J_u J_u^\\top + \\lambda I)^{-1} r,

and the unmeasured velocities keep the closure's velocity zero,
:math:`\\dot q_u = -J_u^{+} J_m \\dot q_m` [rad/s]. The feet do not depend on these joints
(they are not on a foot's chain), but a whole-body model does.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.estimation.lapack import solve

__all__ = ["LoopClosure"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass
class LoopClosure:
    """Solves the unmeasured coordinates of closed chains.

    Attributes:
        pairs: Frame ids of the two anchors of each point constraint.
        unmeasured_v: v indices of the coordinates to solve.
        measured_v: v indices of the other joint coordinates (root excluded).
        damping: :math:`\\lambda` of the Gauss-Newton steps [m^2].
        tolerance: Stop when :math:`\\|r\\|_\\infty` is below this [m].
        max_iterations: Gauss-Newton iterations per solve.
        last_residual: :math:`\\|r\\|_\\infty` after the last solve [m].
    """

    pairs: tuple[tuple[int, int], ...]
    unmeasured_v: Index
    measured_v: Index
    damping: float = 1e-12
    tolerance: float = 1e-7
    max_iterations: int = 8
    last_residual: float = field(default=0.0)

    @classmethod
    def build(
        cls, model: pin.Model, constraints: Sequence[object], unmeasured_v: Index
    ) -> LoopClosure:
        """The closures of ``constraints`` (Pinocchio point constraint models).

        Adds a frame to ``model`` at each anchor (``<constraint>_anchor1`` and ``_anchor2``),
        so call it before creating the model's data.

        Raises:
            ConfigError: A constraint is not a point (``connect``) constraint.
        """
        pairs = []
        for k, constraint in enumerate(constraints):
            if type(constraint).__name__ != "PointAnchorConstraintModel":
                raise ConfigError(f"loop closure: unsupported constraint {constraint!r}")
            name = getattr(constraint, "name", "") or f"constraint{k}"
            ids = []
            for end in (1, 2):
                joint = int(getattr(constraint, f"joint{end}_id"))
                placement = getattr(constraint, f"joint{end}_placement")
                frame = pin.Frame(f"{name}_anchor{end}", joint, placement, pin.FrameType.OP_FRAME)
                ids.append(int(model.addFrame(frame, False)))
            pairs.append((ids[0], ids[1]))
        measured = np.setdiff1d(np.arange(6, model.nv), unmeasured_v)
        return cls(tuple(pairs), np.asarray(unmeasured_v, dtype=np.int64), measured)

    @property
    def active(self) -> bool:
        return bool(self.pairs) and self.unmeasured_v.size > 0

    def residual(self, model: pin.Model, data: pin.Data) -> Array:
        """:math:`r(q)` [m], stacked per constraint (after ``forwardKinematics``)."""
        r = np.empty(3 * len(self.pairs))
        for k, (first, second) in enumerate(self.pairs):
            a = pin.updateFramePlacement(model, data, first).translation
            b = pin.updateFramePlacement(model, data, second).translation
            r[3 * k : 3 * k + 3] = a - b
        return r

    def jacobian(self, model: pin.Model, data: pin.Data) -> Array:
        """:math:`J(q)` [m / rad], all nv columns (after ``computeJointJacobians``)."""
        jacobian = np.empty((3 * len(self.pairs), model.nv))
        for k, (first, second) in enumerate(self.pairs):
            a = pin.getFrameJacobian(model, data, first, WORLD_ALIGNED)[:3]
            b = pin.getFrameJacobian(model, data, second, WORLD_ALIGNED)[:3]
            jacobian[3 * k : 3 * k + 3] = a - b
        return jacobian

    def solve(self, model: pin.Model, data: pin.Data, q: Array, v: Array) -> tuple[Array, Array]:
        """Close the loops: unmeasured coordinates of ``q`` and ``v`` from the measured ones.

        Args:
            model: The robot's Pinocchio model.
            data: Its data; left with the kinematics and joint Jacobians of the result.
            q: Configuration with the measured joints set; the unmeasured ones are the
                initial guess (the previous tick's solution).
            v: Velocity with the measured joints set.

        Returns:
            The completed ``(q, v)``.
        """
        u = self.unmeasured_v
        step = np.zeros(model.nv)
        pin.computeJointJacobians(model, data, q)
        r = self.residual(model, data)
        jacobian = self.jacobian(model, data)
        # J_u^T (J_u J_u^T + lambda I)^-1: the Gauss-Newton step and the velocity map
        pseudo_inverse = self._pseudo_inverse(jacobian[:, u])
        error = float(np.abs(r).max())
        for _ in range(self.max_iterations):
            if error < self.tolerance:
                break
            step[u] = -pseudo_inverse @ r
            q = pin.integrate(model, q, step)
            pin.computeJointJacobians(model, data, q)
            r = self.residual(model, data)
            error = float(np.abs(r).max())
            if error >= self.tolerance:  # not converged: relinearise
                jacobian = self.jacobian(model, data)
                pseudo_inverse = self._pseudo_inverse(jacobian[:, u])
        self.last_residual = error
        # velocities from the last linearisation: at q, or one converged step before it
        v = v.copy()
        v[u] = -pseudo_inverse @ (jacobian[:, self.measured_v] @ v[self.measured_v])
        return q, v

    def _pseudo_inverse(self, jacobian_u: Array) -> Array:
        return solve(jacobian_u @ jacobian_u.T + self._ridge, jacobian_u).T

    @cached_property
    def _ridge(self) -> Array:
        """:math:`\\lambda I` [m^2], added to the Gram matrix (its zeros add exactly)."""
        return self.damping * np.eye(3 * len(self.pairs))
