"""When the MPC uses a plan that OSQP did not fully converge (:class:`Acceptance`).

OSQP (ADMM) converges linearly, and slowly when many inequality rows are active: when the
rider is far from her reference the plan asks the feet for forces at their friction
pyramids' edges on most steps of the horizon (150-205 of the 240-288 pyramid rows active on
the recorded problems of rides that failed), and the warm-started solve may end its
iteration budget at ``maximum iterations reached`` or ``solved inaccurate`` although the
problem is feasible and its first input already near the optimum (the interior-point
solvers, Clarabel and PIQP, solve the same problems in 13-15 iterations).

The standard practice is to accept such a solution when its residuals are bounded. Here,
when a solve ends its budget without converging, it continues from where it stopped (the
same ADMM iterates, its step size as adapted) for :attr:`Acceptance.extra_iterations`;
if it converges then, its plan is used as any other. If not, its plan is still used when

.. math::

    \\|r_{prim}\\|_\\infty \\le \\bar r \\quad \\text{and} \\quad
    \\|u_0^{(j+n)} - u_0^{(j)}\\|_\\infty \\le \\bar d,

its primal residual (the largest violation of a row: dynamics, input boxes, friction
pyramids) and how far its first input moved over those last iterations both within a
fraction of a tolerance. Both are in the QP's scaled units (:mod:`ridempc.mpc.qp`: each
state and input divided by its tolerance, the pyramids' rows by their largest coefficient
times the force tolerance), so the bounds hold the same for every pair. Anything else
(an infeasible problem, a solver error, residuals beyond the bounds) stays a failed plan.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "ACCEPT_CHANGE",
    "ACCEPT_RESIDUAL",
    "EXTRA_ITERATIONS",
    "Acceptance",
]

Array = NDArray[np.float64]

# [iterations] Continued from a solve that ended its budget unconverged: at about 0.05 ms
# an iteration, 5 ms more, only on those solves; on the recorded problems of failed rides
# the first input moved 0.01-0.04 tolerances over it.
EXTRA_ITERATIONS: int = 100
# [tolerances] Largest row violation accepted: a fifth of a tolerance is a fifth of what
# the cost weighs as one unit of error (16 N on a Cassie foot's 80 N force tolerance), and
# the whole-body QP, which turns the plan's forces into torques, holds the contacts'
# friction and load limits itself.
ACCEPT_RESIDUAL: float = 0.2
# [tolerances] Largest move of the first input over the continued iterations accepted: the
# first input is what the rider applies, and a tenth of a tolerance is far below what its
# tracking feels (the recorded unconverged first inputs lay 0.005-0.15 tolerances from
# the interior-point optimum).
ACCEPT_CHANGE: float = 0.1


@dataclass(frozen=True)
class Acceptance:
    """The rule for a plan OSQP did not fully converge (module docstring).

    Attributes:
        extra_iterations: Iterations a solve that ended its budget unconverged continues
            for (0: none, and no plan accepted unconverged).
        residual: Largest primal residual accepted [tolerances].
        change: Largest move of the first input over the continued iterations accepted
            [tolerances].
    """

    extra_iterations: int = EXTRA_ITERATIONS
    residual: float = ACCEPT_RESIDUAL
    change: float = ACCEPT_CHANGE

    def __post_init__(self) -> None:
        if self.extra_iterations < 0:
            raise ValueError(
                f"Acceptance: extra_iterations must be 0 or more, got {self.extra_iterations}"
            )
        for name in ("residual", "change"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0.0):
                raise ValueError(f"Acceptance: {name} must be finite and >= 0, got {value}")

    @property
    def enabled(self) -> bool:
        """Whether an unconverged solve is continued at all."""
        return self.extra_iterations > 0

    def accepts(self, primal_residual: float, before: Array, after: Array) -> bool:
        """Whether an unconverged solve's plan is used.

        Args:
            primal_residual: Its primal residual after the continued iterations
                [tolerances].
            before: Its first input (scaled) when its budget ended.
            after: Its first input (scaled) after the continued iterations.
        """
        if not (self.enabled and np.isfinite(primal_residual)):
            return False
        moved = np.abs(np.asarray(after) - np.asarray(before))
        return bool(
            primal_residual <= self.residual
            and np.all(np.isfinite(moved))
            and moved.max(initial=0.0) <= self.change
        )

    @staticmethod
    def status(status: str) -> str:
        """The plan's status for an accepted unconverged solve, from OSQP's."""
        return f"{status}, accepted"
