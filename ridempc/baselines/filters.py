"""A first-order low-pass filter for the baselines' noisy kinematic signals."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["LowPassFilter"]

Array = NDArray[np.float64]


class LowPassFilter:
    """First-order low-pass :math:`y_k = y_{k-1} + \\alpha (u_k - y_{k-1})`,
    :math:`\\alpha = \\frac{\\omega_c \\Delta t}{1 + \\omega_c \\Delta t}`,
    :math:`\\omega_c = 2 \\pi f_c`, with the step :math:`\\Delta t` [s] taken from the sample
    times. The first sample passes through; ``cutoff_hz = 0`` disables filtering.

    Args:
        cutoff_hz: Cut-off frequency :math:`f_c` [Hz].
    """

    def __init__(self, cutoff_hz: float) -> None:
        if cutoff_hz < 0.0:
            raise ValueError(f"cutoff_hz must be non-negative, got {cutoff_hz}")
        self.omega = 2.0 * np.pi * cutoff_hz
        self._value: Array | None = None
        self._time = 0.0

    def reset(self) -> None:
        self._value = None

    def __call__(self, time: float, sample: Array) -> Array:
        """Filter ``sample`` taken at ``time`` [s]; returns the filtered value."""
        sample = np.asarray(sample, dtype=float)
        if self._value is None or self.omega == 0.0:
            self._value = sample.copy()
        else:
            step = self.omega * max(time - self._time, 0.0)
            self._value = self._value + step / (1.0 + step) * (sample - self._value)
        self._time = time
        return self._value.copy()
