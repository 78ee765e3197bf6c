"""The motion-library format: one ``.npz`` per trajectory and a ``manifest.json`` per pair.

A library is a folder ``motion_library/<robot>-<board>/`` holding:

``manifest.json``
    UTF-8 JSON, the :class:`Manifest` below: ``format`` (``"ridempc-motion-library"``),
    ``version`` (1), ``robot``, ``board`` and ``entries``, one :class:`EntryRecord` per stored
    trajectory: its name, kind and target, the file and the SHA-256 of that file's bytes,
    IPOPT's status, iterations and times, the largest collocation-defect violation, the
    grid (``n_intervals``, ``dt``) and array sizes (``nx``, ``nu``, ``n_parameters``), the
    re-simulation drift, the neighbour it was warm-started from, and the problem's
    ``metadata`` (options, contact schedule).

``<kind>-<target>.npz``
    A NumPy ``.npz`` archive of plain arrays (no object arrays, so it loads with
    ``allow_pickle=False``; loading never runs code from a file), named in :data:`ARRAYS`:
    ``times`` (N+1) [s], ``states`` (N+1 x nx), ``inputs`` (N x nu), ``midpoints``
    (N x nx, the Hermite-Simpson midpoint states), ``parameters`` (N x n_p, per-interval
    mode data such as which feet are on the deck), ``state_names`` (nx) and
    ``input_names`` (nu) as fixed-width Unicode strings. Units are SI: [m], [rad], [m/s],
    [rad/s], [N], [N m]; each pair's state and input layout is in its problem module.

Loading checks the manifest's fields and types, that each file is the manifest's name for
its entry (no paths), its hash, its arrays' presence, dtypes, shapes and finiteness, and
refuses anything else with a :class:`~ridempc.errors.ConfigError` naming the file.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field

from ridempc.units import (
    CheckedModel,
    Count,
    NonNegative,
    NonNegativeCount,
    Positive,
    PositiveCount,
    Real,
)

__all__ = [
    "ARRAYS",
    "FORMAT",
    "MANIFEST",
    "SUCCESS",
    "VERSION",
    "DriftRecord",
    "EntryRecord",
    "Manifest",
]

FORMAT = "ridempc-motion-library"
VERSION = 1
MANIFEST = "manifest.json"
SUCCESS = "Solve_Succeeded"

# Array name -> (dtype kind, shape in terms of the record's sizes).
ARRAYS: dict[str, tuple[str, tuple[str, ...]]] = {
    "times": ("f", ("N+1",)),
    "states": ("f", ("N+1", "nx")),
    "inputs": ("f", ("N", "nu")),
    "midpoints": ("f", ("N", "nx")),
    "parameters": ("f", ("N", "n_parameters")),
    "state_names": ("U", ("nx",)),
    "input_names": ("U", ("nu",)),
}

NAME_PATTERN = r"^[a-z][a-z0-9_]*-[0-9]+\.[0-9]{2}$"


class _Strict(CheckedModel):
    """Strict numbers (no NaN, no strings or booleans for numbers), no unknown keys."""


class DriftRecord(_Strict):
    """Re-simulation drift (see :mod:`ridempc.trajopt.validation`), state units."""

    local: NonNegative = Field(description="largest one-interval gap, every state")
    local_board: NonNegative = Field(description="largest one-interval gap, board states")
    board: NonNegative = Field(description="largest gap of the board-only rollout")
    board_final: dict[str, NonNegative]
    open_loop_time: NonNegative = Field(description="[s] open loop within tolerance")
    integrator: str


class EntryRecord(_Strict):
    """One stored trajectory in the manifest."""

    name: str = Field(pattern=NAME_PATTERN)
    kind: str = Field(pattern=r"^[a-z][a-z0-9_]*$")
    target: Annotated[Real, Field(gt=0.0, le=10.0)]  # [m/s]; every pair checks its own bound
    file: str = Field(description="the entry's file, always '<name>.npz'")
    sha256: str = Field(pattern=r"^[0-9a-f]{64}$")
    status: Literal["Solve_Succeeded"]
    iterations: NonNegativeCount
    solve_time_s: NonNegative
    build_time_s: NonNegative
    max_violation: NonNegative
    n_intervals: PositiveCount
    dt: Annotated[Positive, Field(le=1.0)]  # [s]; a collocation step above 1 s resolves nothing
    nx: PositiveCount
    nu: PositiveCount
    n_parameters: NonNegativeCount
    drift: DriftRecord
    warm_start: str | None
    metadata: dict[str, Any]

    def sizes(self) -> dict[str, int]:
        """Values of the shape symbols of :data:`ARRAYS`."""
        n = self.n_intervals
        return {
            "N": n,
            "N+1": n + 1,
            "nx": self.nx,
            "nu": self.nu,
            "n_parameters": self.n_parameters,
        }


class Manifest(_Strict):
    """``manifest.json`` of one robot-board pair."""

    format: Literal["ridempc-motion-library"]
    version: Annotated[Count, Field(ge=VERSION, le=VERSION)]  # the only version there is
    robot: str
    board: str
    entries: tuple[EntryRecord, ...]

    def entry(self, name: str) -> EntryRecord | None:
        return next((e for e in self.entries if e.name == name), None)
