"""The MPC QP's rows held in one OSQP class, so that new bounds never re-factor its KKT.

OSQP sorts each row of :math:`l \\le A z \\le u` into a class and gives it a step size
:math:`\\rho` of its own: *loose* (both bounds infinite: :math:`\\rho_{min}`), *equality*
(:math:`u - l` below :data:`RHO_TOL`: :math:`10^3 \\rho`) or *inequality* (:math:`\\rho`).
A row that changes class between two solves changes :math:`\\rho` in its KKT matrix, which
OSQP then re-factors once for the bounds, before (and besides) the factorisation the new
matrix values cost. On the skateboard a foot's force rows are free while it stands and
pinned to zero while it swings (loose, then equality), and its load row is an inequality
while it stands and an equality while it swings, so half the solves re-factored twice.

:class:`RowClasses` holds each row in the class it was last set up in and writes the
bounds a problem asks for in that class's terms, each the same constraint:

- a free row held as an **equality**: its coefficients zeroed and its bounds
  :math:`0 \\le 0 \\le 0` (no constraint, exactly);
- a free row held as an **inequality**: bounds :math:`\\pm` :data:`WIDE` (never reached);
- an equality :math:`b` held as an **inequality**: bounds :math:`b \\pm` :data:`BAND`,
  within the solver's own tolerance of :math:`b`.

Only a row that must change class does: a loose row that gets a bound, or an equality
row that gets an inequality. It is then held in its new class. So each row changes class
at most twice in a ride, and a ride whose rows never change class is solved as before,
to the bit.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "BAND",
    "EQUALITY",
    "INEQUALITY",
    "LOOSE",
    "LOOSE_BOUND",
    "RHO_TOL",
    "WIDE",
    "RowClasses",
]

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

LOOSE, INEQUALITY, EQUALITY = -1, 0, 1  # OSQP's own codes for the classes (constr_type)
RHO_TOL: float = 1e-4  # OSQP_RHO_TOL: a row whose u - l is below it is an equality
LOOSE_BOUND: float = 1e26  # OSQP_INFTY x OSQP_MIN_SCALING: bounds beyond it are infinite
# A free row's bounds held as an inequality, in the QP's scaled units (tolerances): a
# plan's deviations are of order one tolerance, so a million never binds.
WIDE: float = 1e6
# Half the band of an equality held as an inequality, in tolerances: u - l = 2e-4 keeps
# OSQP's inequality class (above RHO_TOL) and is a fifth of its 1e-3 residual tolerance.
BAND: float = RHO_TOL


class RowClasses:
    """Each row's class as OSQP holds it, and the bounds written in its terms.

    Attributes:
        held: Each row's class (:data:`LOOSE`, :data:`INEQUALITY`, :data:`EQUALITY`).
        switches: Calls to :meth:`hold` that had to change a row's class.
    """

    def __init__(self, lower: Array, upper: Array, value_rows: IntArray) -> None:
        """Hold the rows in the classes of the bounds the QP is set up with.

        Args:
            lower: The set-up's lower bounds (one per row).
            upper: Its upper bounds.
            value_rows: The row of each stored value of the constraint matrix.
        """
        self.held = self.wanted(lower, upper)
        self.switches = 0
        self._value_rows = np.asarray(value_rows)

    @staticmethod
    def wanted(lower: Array, upper: Array) -> IntArray:
        """The class OSQP gives each row of these bounds."""
        free = (lower < -LOOSE_BOUND) & (upper > LOOSE_BOUND)
        equal = upper - lower < RHO_TOL
        return np.where(free, LOOSE, np.where(equal, EQUALITY, INEQUALITY)).astype(np.int64)

    def hold(self, values: Array, lower: Array, upper: Array) -> tuple[Array, Array, Array]:
        """The constraint values and bounds in the held classes (module docstring); the
        rows that must change class change, and are held in their new one.

        Args:
            values: The constraint matrix's stored values (as ``value_rows``).
            lower: The lower bounds, one per row (may be infinite).
            upper: The upper bounds.

        Returns:
            The values and bounds to write (the arguments themselves where nothing
            changes, else new arrays).
        """
        wanted = self.wanted(lower, upper)
        held = self.held
        differ = wanted != held
        if not differ.any():
            return values, lower, upper
        must = differ & ((held == LOOSE) | ((held == EQUALITY) & (wanted == INEQUALITY)))
        if must.any():
            held[must] = wanted[must]
            self.switches += 1
        lower, upper = lower.copy(), upper.copy()
        zero = (wanted == LOOSE) & (held == EQUALITY)
        if zero.any():
            values = values.copy()
            values[zero[self._value_rows]] = 0.0
            lower[zero] = upper[zero] = 0.0
        wide = (wanted == LOOSE) & (held == INEQUALITY)
        lower[wide], upper[wide] = -WIDE, WIDE
        band = (wanted == EQUALITY) & (held == INEQUALITY)
        middle = 0.5 * (lower[band] + upper[band])
        lower[band], upper[band] = middle - BAND, middle + BAND
        return values, lower, upper
