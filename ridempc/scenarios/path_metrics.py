"""How well a ride followed its commanded path, from the judge's log (the true base).

- ``cross_track_rmse`` [m]: the base's distance across the path
  (:meth:`~ridempc.scenarios.path.PathGeometry.cross_track`), root mean square over the
  samples from the later of the scenario's ``metrics_start`` and the path's ``start`` until
  the end of the ride (or the fall);
- for a slalom, ``gates`` (how many) and ``gates_passed``: a gate is passed when the base
  crosses the line through it, square to the x axis, within half the ``gate_width`` of its
  centre, and ``max_cross_track`` [m].
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ridempc.scenarios.path import PathFrame, PathGeometry, SlalomPath
from ridempc.scenarios.scenario import Scenario

__all__ = ["gates_passed", "path_metrics"]


def gates_passed(path: SlalomPath, xy: np.ndarray) -> int:
    """How many of the slalom's gates the track ``xy`` [m] (n, 2) passes through."""
    passed = 0
    for gate in path.gate_points():
        crossed = np.flatnonzero((xy[:-1, 0] < gate[0]) & (xy[1:, 0] >= gate[0]))
        if crossed.size:
            k = crossed[0]
            share = (gate[0] - xy[k, 0]) / (xy[k + 1, 0] - xy[k, 0])
            y = xy[k, 1] + share * (xy[k + 1, 1] - xy[k, 1])
            passed += int(abs(y - gate[1]) <= 0.5 * path.gate_width)
    return passed


def path_metrics(log: dict[str, np.ndarray], scenario: Scenario) -> dict[str, Any]:
    """The path-following figures of a ride (empty without a path or a log)."""
    path = scenario.path
    if path is None or not log:
        return {}
    window = log["time"] >= max(scenario.metrics_start, path.start)
    first = int(np.searchsorted(log["time"], path.start))
    if first >= len(log["time"]):
        return {}
    start = log["base_position"][first]
    frame = PathFrame(float(start[0]), float(start[1]), float(log["yaw"][first]))
    xy = frame.to_path(log["base_position"][:, :2])
    cross = PathGeometry(path).cross_track(xy)[window]
    out: dict[str, Any] = {
        "cross_track_rmse": float(np.sqrt(np.mean(cross**2))) if cross.size else None,
        "max_cross_track": float(np.max(np.abs(cross))) if cross.size else None,
    }
    if isinstance(path, SlalomPath):
        out["gates"] = int(path.gates)
        out["gates_passed"] = int(gates_passed(path, xy))
    return out
