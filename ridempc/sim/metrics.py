"""Figures of a run, computed from the judge's log (true state), never from the controller's view.

- ``velocity_rmse`` [m/s]: :math:`\\sqrt{\\overline{(v_{fwd} - v^*)^2}}`, with
  :math:`v_{fwd} = \\cos\\psi\\, \\dot x + \\sin\\psi\\, \\dot y` the base's forward speed in its
  heading frame and :math:`v^*` the commanded speed;
- ``yaw_rate_rmse`` [rad/s]: :math:`\\sqrt{\\overline{(\\dot\\psi - \\dot\\psi^*)^2}}`;
- ``peak_torque`` [N m] per motor, and the largest ratio of peak to limit;
- ``base_height_drift`` [m]: final minus initial base height;
- ``controller_update_ms``: median and p99 of the controller's update time.

Both RMSEs are taken over the samples from the scenario's ``metrics_start`` until the
end of the run (or the fall).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Scenario
from ridempc.sim.simulation import RunResult

__all__ = ["run_metrics"]


def _rmse(error: np.ndarray) -> float | None:
    return float(np.sqrt(np.mean(error**2))) if error.size else None


def run_metrics(result: RunResult, scenario: Scenario, robot: Robot) -> dict[str, Any]:
    log = result.log
    if not log:
        return {}
    window = log["time"] >= scenario.metrics_start
    torque = np.abs(log["motor_torque"])
    peak = torque.max(axis=0)
    limits = np.array([m.torque_limit for m in robot.motors])
    metrics: dict[str, Any] = {
        "velocity_rmse": _rmse(log["forward_velocity"][window] - log["command_velocity"][window]),
        "yaw_rate_rmse": _rmse(log["yaw_rate"][window] - log["command_yaw_rate"][window]),
        "peak_torque": {
            m.name: round(float(p), 3) for m, p in zip(robot.motors, peak, strict=True)
        },
        "peak_torque_ratio": float(np.max(peak / limits)),
        "base_height_initial": float(log["base_position"][0, 2]),
        "base_height_drift": float(log["base_position"][-1, 2] - log["base_position"][0, 2]),
        "distance_travelled": float(
            np.linalg.norm(log["base_position"][-1, :2] - log["base_position"][0, :2])
        ),
    }
    if result.controller_times.size:
        ms = 1e3 * result.controller_times
        metrics["controller_update_ms"] = {
            "median": float(np.median(ms)),
            "p99": float(np.percentile(ms, 99)),
        }
    return metrics
