"""Zero-order hold of a stack of linear systems (eq. 18): the discrete :math:`A_k` and the
integral that turns :math:`B^c_k` and the affine term into their discrete counterparts."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import matrix_balance

__all__ = ["zero_order_hold"]

Array = NDArray[np.float64]
_TAYLOR_ORDER = 12  # a multiple of 3 (Paterson-Stockmeyer in X^3)
_COEFFICIENTS = tuple(1.0 / math.factorial(j + 1) for j in range(_TAYLOR_ORDER + 1))


def zero_order_hold(a_c: Array, dt: float) -> tuple[Array, Array]:
    """:math:`e^{A \\Delta t}` and :math:`\\Phi = \\int_0^{\\Delta t} e^{A s} ds` of a stack of
    matrices (N x nx x nx), by scaling and squaring a Taylor series.

    With :math:`h = \\Delta t / 2^s` small enough that :math:`\\|A h\\|_1 \\le 1/2`,
    :math:`\\Phi(h) = h \\sum_{j=0}^{K} (A h)^j / (j + 1)!` (truncation below
    :math:`10^{-15}` for K = 12, evaluated as a polynomial in :math:`(A h)^3` whose
    coefficients are quadratics in :math:`A h`: six matrix products instead of twelve),
    :math:`e^{A h} = I + A \\Phi(h)`, then s doublings
    :math:`\\Phi(2h) = (I + e^{A h}) \\Phi(h)`, :math:`e^{2 A h} = (e^{A h})^2`. This is the
    top block row of the exponential of the augmented matrix (module docstring): the
    discrete :math:`B_k = \\Phi B^c_k` and :math:`g_k = \\Phi f_k`, computed on nx x nx
    blocks only (small enough for BLAS to stay single-threaded, which on a busy machine
    is ten times faster than SciPy's ``expm`` of the (nx + nu + 1)-square matrix). Equal
    matrices in the stack are computed once.

    The stack is first balanced by one diagonal similarity :math:`T` (powers of two, so
    exact), that of the entry-wise largest magnitudes over the stack (LAPACK's ``gebal``):
    :math:`e^{A \\Delta t} = T e^{T^{-1} A T \\Delta t} T^{-1}` and likewise for
    :math:`\\Phi`. The pairs' matrices mix units (a force's moment on a velocity next to
    a position's unit rate), so their 1-norm overstates how fast they are: the
    skateboard's :math:`\\|A \\Delta t\\|_1` of 22 is 1.6 balanced, four squarings fewer.
    """
    a_c = np.asarray(a_c, dtype=float)
    if a_c.ndim == 3 and len(a_c) > 1:  # a stack: each distinct matrix once (a steady
        keys = [m.tobytes() for m in a_c]  # reference repeats one over the horizon)
        distinct = {key: i for i, key in reversed(list(enumerate(keys)))}
        if len(distinct) < len(a_c):
            first = list(distinct.values())
            exponential, phi = zero_order_hold(a_c[first], dt)
            where = {key: j for j, key in enumerate(distinct)}
            pick = [where[key] for key in keys]
            return exponential[pick], phi[pick]
    if a_c.size == 0:
        return a_c.copy(), a_c * dt
    _, (t, _) = matrix_balance(
        np.abs(a_c).reshape(-1, *a_c.shape[-2:]).max(axis=0), permute=False, separate=True
    )
    exponential, phi = _balanced(a_c * (t[None, :] / t[:, None]), dt)
    similar = t[:, None] / t[None, :]  # T X T^{-1}
    return exponential * similar, phi * similar


def _balanced(a_c: Array, dt: float) -> tuple[Array, Array]:
    eye = np.eye(a_c.shape[-1])
    norm = float(np.max(np.abs(a_c).sum(axis=-2))) * dt if a_c.size else 0.0
    squarings = max(0, int(np.ceil(np.log2(norm / 0.5)))) if norm > 0.5 else 0
    h = dt / 2**squarings
    x = a_c * h
    x2 = x @ x
    x3 = x2 @ x
    powers = (eye, x, x2)
    series = _COEFFICIENTS[-1] * eye  # Paterson-Stockmeyer: Horner in X^3
    for block in range(_TAYLOR_ORDER // 3 - 1, -1, -1):
        start = 3 * block
        near = sum(c * p for c, p in zip(_COEFFICIENTS[start : start + 3], powers, strict=True))
        series = near + x3 @ series
    phi = h * series
    exponential = eye + a_c @ phi
    for _ in range(squarings):
        phi = phi + exponential @ phi
        exponential = exponential @ exponential
    return exponential, phi
