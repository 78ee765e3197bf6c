"""The estimator's small dense solves and SVDs, through LAPACK with nothing around it.

Every tick the estimator solves a few systems of 6 to 24 rows (the Kalman gain, the loop
closure's pseudo-inverse, the contact forces) and takes the SVD of a few contact points.
``np.linalg.solve`` and ``np.linalg.svd`` call LAPACK's ``dgesv`` (LU with partial
pivoting) and ``dgesdd`` (divide and conquer), but spend 7-10 us around each call
(argument checks, an error-state context, type dispatch): more than the routine itself at
these sizes. :func:`solve` and :func:`svd` call the same routines through SciPy's LAPACK
wrappers and return the same numbers, laid out as NumPy returns them (C order: the
products that follow see the same memory layout and so add up in the same order).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import lapack

__all__ = ["solve", "svd"]

Array = NDArray[np.float64]


def solve(a: Array, b: Array) -> Array:
    """:math:`x = a^{-1} b` by LU with partial pivoting, as ``np.linalg.solve(a, b)``.

    Args:
        a: Square matrix [n x n].
        b: Right-hand side [n] or [n x k].

    Raises:
        np.linalg.LinAlgError: ``a`` is singular.
    """
    _, _, x, info = lapack.dgesv(a, b)
    if info > 0:
        raise np.linalg.LinAlgError("Singular matrix")
    if info < 0:
        raise ValueError(f"dgesv: argument {-info} is invalid")
    return np.ascontiguousarray(x)


def svd(a: Array) -> tuple[Array, Array, Array]:
    """:math:`a = u\\, \\mathrm{diag}(s)\\, v^\\top` with square :math:`u` and :math:`v^\\top`,
    as ``np.linalg.svd(a, full_matrices=True)``: ``(u, s, vt)``, ``s`` descending.

    Raises:
        np.linalg.LinAlgError: The SVD did not converge.
    """
    u, s, vt, info = lapack.dgesdd(a, compute_uv=1, full_matrices=1)
    if info > 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    if info < 0:
        raise ValueError(f"dgesdd: argument {-info} is invalid")
    return np.ascontiguousarray(u), s, np.ascontiguousarray(vt)
