"""The estimator's small dense solves and SVDs, through LAPACK with nothing around it.

Every tick the estimator solves a few systems of 6 to 24 rows (the Kalman gain, the loop
closure's pseudo-inverse, the contact forces) and takes the SVD of a few contact points.
``np.linalg.solve`` and ``np.linalg.svd`` call LAPACK's ``dgesv`` (LU with partial
pivoting) and ``dgesdd`` (divide and conquer), but spend 7-10 us around each call
(argument checks, an error-state context, type dispatch): more than the routine itself at
these sizes. :func:`solve` and :func:`svd` call the same routines through SciPy's LAPACK
wrappers and return the same numbers, laid out as NumPy returns them (C order: the
products that follow see the same memory layout and so add up in the same order);
:func:`pinv` is ``np.linalg.pinv``'s arithmetic on :func:`svd`'s thin factors.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import lapack

__all__ = ["pinv", "solve", "svd"]

Array = NDArray[np.float64]

# np.linalg.pinv's default relative cut-off: singular values this far below the largest are
# rounding, not rank, and inverting them would amplify noise by 1e15
_PINV_RCOND: float = 1e-15


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
    return _gesdd(a, full_matrices=True)


def pinv(a: Array) -> Array:
    """The Moore-Penrose pseudo-inverse of ``a`` [m x n], as ``np.linalg.pinv(a)``: the thin
    SVD's inverse singular values, those at most ``1e-15`` times the largest set to zero
    (NumPy's default cut-off), :math:`a^+ = v\\, \\mathrm{diag}(1/s)\\, u^\\top`.

    Raises:
        np.linalg.LinAlgError: The SVD did not converge.
    """
    u, s, vt = _gesdd(a, full_matrices=False)
    large = s > _PINV_RCOND * np.max(s)
    s = np.divide(1.0, s, where=large, out=s)
    s[~large] = 0.0
    return np.matmul(vt.T, np.multiply(s[:, np.newaxis], u.T))


def _gesdd(a: Array, full_matrices: bool) -> tuple[Array, Array, Array]:
    """``dgesdd``'s ``(u, s, vt)`` in C order, square (``full_matrices``) or thin."""
    u, s, vt, info = lapack.dgesdd(a, compute_uv=1, full_matrices=int(full_matrices))
    if info > 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    if info < 0:
        raise ValueError(f"dgesdd: argument {-info} is invalid")
    return np.ascontiguousarray(u), s, np.ascontiguousarray(vt)
