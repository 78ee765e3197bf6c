"""The plan's first input drawn towards the last one applied (a penalty on its step).

The whole-body QP realises the plan's first input :math:`u_0` until the next solve, and
the MPC, whose state weights are tight and whose deck roll is a fast mode it can move in
one step, answers each new estimate with a new :math:`u_0`: on the skateboard, while a foot
swings back to the deck, the three standing feet's deck forces swap between solves, and a
foot left at the floor's least force can lose the deck (``docs/tuning.md``).

With :math:`u_p` the last plan's first input, a penalty :math:`\\|u_0 - u_p\\|^2_S` on top of
the MPC's :math:`\\|u_0 - \\bar u_0\\|^2_R` (eq. 19, drawn to the reference :math:`\\bar u`)
is the single quadratic

.. math::

    \\|u_0 - \\bar u_0\\|^2_R + \\|u_0 - u_p\\|^2_S = \\|u_0 - \\tilde u_0\\|^2_{R + S}
        + \\text{const}, \\qquad
    \\tilde u_0 = (R + S)^{-1} (R \\bar u_0 + S u_p)

for diagonal :math:`R, S`: the QP keeps its shape, with step 0's input weights :math:`R + S`
and reference :math:`\\tilde u_0`. Later steps are free to move, so a change is spread over
the solves rather than refused.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.problem import MpcProblem

__all__ = ["hold_first_input"]

Array = NDArray[np.float64]


def hold_first_input(problem: MpcProblem, previous: Array, weights: Array) -> MpcProblem:
    """``problem`` with :math:`\\|u_0 - u_p\\|^2_S` added to its cost (module docstring).

    Args:
        problem: The tick's problem.
        previous: :math:`u_p` (nu), the input applied since the last solve.
        weights: Diagonal of :math:`S` (nu), in [1 / input unit^2]; zero: no penalty.

    Returns:
        The problem with per-step input weights (N x nu) and step 0's reference and weights
        merged; ``problem`` itself when every weight is zero.

    Raises:
        ValueError: Shapes that do not match the problem's inputs, or negative weights.
    """
    nu = problem.nu
    previous = np.asarray(previous, dtype=float)
    weights = np.asarray(weights, dtype=float)
    if previous.shape != (nu,) or weights.shape != (nu,):
        raise ValueError(
            f"hold_first_input: previous {previous.shape} and weights {weights.shape} must "
            f"both be ({nu},)"
        )
    if np.any(weights < 0.0):
        raise ValueError("hold_first_input: weights must be non-negative")
    if not np.any(weights):
        return problem
    r = np.array(np.broadcast_to(problem.input_weights, problem.input_reference.shape))
    u_ref = problem.input_reference.copy()
    total = r[0] + weights
    held = weights > 0.0
    u_ref[0, held] = (r[0, held] * u_ref[0, held] + weights[held] * previous[held]) / total[held]
    r[0] = total
    return replace(problem, input_weights=r, input_reference=u_ref)
