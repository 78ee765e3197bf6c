"""How soon the platforms are level again after each step (Hovershoes paper, Fig. 10).

For each step edge of the scenario's terrain at :math:`x_e` [m], the ride crosses it when
the last platform's origin (the wheel's axle on the Hovershoes) passes :math:`x_e`; from
then until the next edge is crossed (or the ride ends), ``level_after_s`` [s] is the time
after which every platform stays within ``LEVEL_TOLERANCE`` of level (the tilt of its z
axis from the vertical): 0 when none ever left it, None when one is still tilted at the
end of that span (the next edge, or the ride's end) or the edge was never crossed. Read
from the judge's log (true state).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ridempc.scenarios.scenario import Scenario
from ridempc.scenarios.terrain import step_edges
from ridempc.sim.metrics import board_tilt

__all__ = ["LEVEL_TOLERANCE", "step_levelling"]

LEVEL_TOLERANCE: float = math.radians(2.0)  # [rad] the "within 2 deg of level"


def step_levelling(log: dict[str, np.ndarray], scenario: Scenario) -> dict[str, Any]:
    """``{"steps": [{"x_m", "crossed_s", "level_after_s"}, ...]}`` for a terrain with steps
    and a board; empty otherwise."""
    edges = step_edges(scenario.terrain)
    if not edges or "board_position" not in log or not len(log.get("time", ())):
        return {}
    time = log["time"]
    last_x = log["board_position"][:, :, 0].min(axis=1)  # the platform furthest behind
    tilted = board_tilt(log["board_quaternion"]).max(axis=1) > LEVEL_TOLERANCE
    crossings = []
    for x in edges:
        passed = np.flatnonzero(last_x >= x)
        crossings.append(int(passed[0]) if len(passed) else None)
    steps = []
    for k, (x, start) in enumerate(zip(edges, crossings, strict=True)):
        entry: dict[str, Any] = {"x_m": x, "crossed_s": None, "level_after_s": None}
        steps.append(entry)
        if start is None:
            continue
        entry["crossed_s"] = round(float(time[start]), 4)
        later = [c for c in crossings[k + 1 :] if c is not None]
        stop = later[0] if later else len(time)
        span = tilted[start:stop]
        if span[-1]:
            continue  # still tilted at the next edge or the ride's end
        last = np.flatnonzero(span)
        settled = start + int(last[-1]) + 1 if len(last) else start
        entry["level_after_s"] = round(float(time[min(settled, len(time) - 1)] - time[start]), 4)
    return {"steps": steps}
