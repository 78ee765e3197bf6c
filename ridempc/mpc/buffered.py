"""A CasADi function called through NumPy buffers: no CasADi matrices per call.

Calling a CasADi function from Python converts each argument to a ``DM`` and each result
back to NumPy, which for the MPC's small per-tick functions costs more than evaluating
them. :class:`BufferedFunction` binds NumPy arrays to the function's inputs and outputs
once (CasADi's ``buffer``), copies the arguments in, runs it, and scatters each output's
non-zeros into a dense array, the same values :func:`numpy.asarray` of the ``DM`` result
would hold.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from numpy.typing import NDArray

__all__ = ["BufferedFunction"]

Array = NDArray[np.float64]


class BufferedFunction:
    """``function`` evaluated through NumPy buffers (module docstring).

    Args:
        function: A CasADi function with dense inputs.

    Raises:
        ValueError: An input is not dense (its non-zeros would not be its entries).
    """

    def __init__(self, function: ca.Function) -> None:
        for i in range(function.n_in()):
            if not function.sparsity_in(i).is_dense():
                raise ValueError(f"BufferedFunction: input {i} of {function.name()} is sparse")
        self.function = function
        self._buffer, self._run = function.buffer()
        self._args = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        self._results = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        # CasADi's stubs list a size argument its SWIG wrapper takes from the buffer itself.
        for i, array in enumerate(self._args):
            self._buffer.set_arg(i, memoryview(array))  # type: ignore[call-arg, arg-type]
        for i, array in enumerate(self._results):
            self._buffer.set_res(i, memoryview(array))  # type: ignore[call-arg, arg-type]
        self._where = []
        for i in range(function.n_out()):
            triplet = function.sparsity_out(i).get_triplet()
            rows, cols = (np.array(v, dtype=np.int64) for v in triplet)
            self._where.append((rows, cols, (function.size1_out(i), function.size2_out(i))))

    def nonzeros(self, *args: Array) -> list[Array]:
        """The outputs' non-zeros at ``args`` (each taken in column-major order, as
        CasADi's): the buffers themselves, overwritten by the next call."""
        for target, value in zip(self._args, args, strict=True):
            target[:] = np.ravel(value, order="F")
        self._run()
        return self._results

    def __call__(self, *args: Array) -> list[Array]:
        """The outputs, dense, at ``args`` (as :meth:`nonzeros`)."""
        out = []
        for (rows, cols, shape), values in zip(self._where, self.nonzeros(*args), strict=True):
            dense = np.zeros(shape)
            dense[rows, cols] = values
            out.append(dense)
        return out
