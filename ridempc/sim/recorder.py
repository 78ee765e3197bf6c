"""Time-series log of a run, written as one ``log.npz`` (named arrays, no pickle)."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ridempc.io import atomic_write_npz

__all__ = ["Recorder"]


class Recorder:
    """Collects named rows at the logging rate; each name keeps a fixed shape."""

    def __init__(self) -> None:
        self._columns: dict[str, list[NDArray[np.float64]]] = defaultdict(list)

    def append(self, **values: float | NDArray[np.float64]) -> None:
        for name, value in values.items():
            self._columns[name].append(
                np.array(value, dtype=float)
            )  # a copy: MuJoCo arrays are views

    def arrays(self) -> dict[str, NDArray[np.float64]]:
        return {name: np.stack(rows) for name, rows in self._columns.items() if rows}

    def __len__(self) -> int:
        return len(self._columns.get("time", []))

    def save(self, path: Path) -> None:
        atomic_write_npz(path, self.arrays())
