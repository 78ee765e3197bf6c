"""One persistent OSQP workspace for a QP solved every tick, without the wrapper's overhead.

OSQP's Python class (``osqp.OSQP``, 1.x) does more per call than a 500 Hz loop wants:
``update`` looks the solver's infinity up through ``importlib`` twice to clip the bounds and
keeps copies of the data for derivatives; ``solve`` copies some thirty ``info`` fields into
a namespace. On Cassie's whole-body QP that was about 0.08 ms of a 0.7 ms tick. So, once
set up through the public class, the workspace drives the compiled solver it holds
(``OSQP._solver``: ``update_data_vec``, ``update_data_mat``, ``solve``, ``info``,
``solution``) directly, with the same clipping of infinite bounds to
:math:`\\pm` ``OSQP_INFTY``; where a version of the package does not expose it, the public
methods serve, with the same results.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import osqp
import scipy.sparse as sparse
from numpy.typing import NDArray

from ridempc.interrupts import osqp_returned

__all__ = ["OSQP_INFINITY", "OsqpResult", "OsqpWorkspace"]

Array = NDArray[np.float64]
OSQP_INFINITY: float = float(osqp.constant("OSQP_INFTY"))  # its bound for a free row
_COMPILED_API: tuple[str, ...] = ("update_data_vec", "update_data_mat", "solve", "info", "solution")


@dataclass(frozen=True)
class OsqpResult:
    """What one solve returned.

    Attributes:
        x: Primal solution (a copy).
        y: Dual solution (a copy).
        status: OSQP's status string (``solved``, ``solved inaccurate``, ...).
        iterations: ADMM iterations.
        polished: Whether polishing succeeded.
        run_time: OSQP's own time for the solve (factorisation, iterations, polish) [s].
    """

    x: Array
    y: Array
    status: str
    iterations: int
    polished: bool
    run_time: float


class OsqpWorkspace:
    """An OSQP workspace, set up once, then updated in place and solved warm.

    Args:
        P: Objective Hessian, upper triangle, CSC.
        q: Objective gradient.
        A: Constraint matrix, CSC.
        l: Lower bounds (``-inf`` where free).
        u: Upper bounds (``inf`` where free).
        settings: OSQP settings.
    """

    def __init__(
        self,
        P: sparse.csc_matrix,  # noqa: N803 - the QP's usual names
        q: Array,
        A: sparse.csc_matrix,  # noqa: N803
        l: Array,  # noqa: E741
        u: Array,
        settings: Mapping[str, Any],
    ) -> None:
        self.wrapper = osqp.OSQP()
        self.wrapper.setup(P, q, A, l, u, **settings)
        compiled = getattr(self.wrapper, "_solver", None)
        usable = compiled is not None and all(hasattr(compiled, a) for a in _COMPILED_API)
        self._compiled: Any = compiled if usable else None

    @property
    def direct(self) -> bool:
        """Whether the compiled solver is driven directly (else the public methods)."""
        return self._compiled is not None

    def update(self, q: Array, l: Array, u: Array, Px: Array, Ax: Array) -> None:  # noqa: E741, N803
        """New vectors, and new values for the fixed patterns of :math:`P` and :math:`A`."""
        compiled = self._compiled
        if compiled is None:
            self.wrapper.update(q=q, l=l, u=u, Px=Px, Ax=Ax)
            return
        compiled.update_data_vec(
            q=q, l=np.maximum(l, -OSQP_INFINITY), u=np.minimum(u, OSQP_INFINITY)
        )
        compiled.update_data_mat(P_x=Px, P_i=None, A_x=Ax, A_i=None)

    def solve(self) -> OsqpResult:
        """Solve from the last iterates (warm, if ``warm_starting`` is set).

        Raises:
            Interrupted: The command was interrupted (:mod:`ridempc.interrupts`).
        """
        compiled = self._compiled
        if compiled is None:
            result = self.wrapper.solve(raise_error=False)
            info, x, y = result.info, result.x, result.y
        else:
            compiled.solve()
            info, x, y = compiled.info, compiled.solution.x, compiled.solution.y
        osqp_returned(int(info.status_val))
        return OsqpResult(
            x=np.array(x, dtype=float),
            y=np.array(y, dtype=float),
            status=str(info.status),
            iterations=int(info.iter),
            polished=int(info.status_polish) == 1,
            run_time=float(info.run_time),
        )
