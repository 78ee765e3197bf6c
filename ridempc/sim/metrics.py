"""Figures of a run, computed from the judge's log (true state), never from the controller's view.

- ``velocity_rmse`` [m/s]: :math:`\\sqrt{\\overline{(v_{fwd} - v^*)^2}}`, with
  :math:`v_{fwd} = \\cos\\psi\\, \\dot x + \\sin\\psi\\, \\dot y` the base's forward speed in its
  heading frame and :math:`v^*` the commanded speed;
- ``yaw_rate_rmse`` [rad/s]: :math:`\\sqrt{\\overline{(\\dot\\psi - \\dot\\psi^*)^2}}`;
- ``peak_torque`` [N m] per motor, and the largest ratio of peak to limit;
- ``board_max_tilt`` [rad] and ``board_max_speed`` [m/s] of the board's platforms;
- ``roll_rmse`` [rad]: the deck's roll against the commanded roll, where a roll is commanded;
- ``foot_spacing_rmse`` [m]: for two independent platforms, their lateral distance across
  the rider's heading against the starting spacing plus twice the commanded lateral offset;
- ``base_height_drift`` [m]: final minus initial base height;
- ``estimator_velocity_rmse`` [m/s] and ``estimator_position_rmse`` [m]: the controller's
  state estimate of the base velocity and position against the truth,
  :math:`\\sqrt{\\overline{\\|\\hat v - v\\|^2}}`, over the whole run (rows with an estimate),
  when the controller has an estimator;
- ``target_velocity`` and ``final_velocity`` [m/s]: for a push-off scenario, its target and
  the board's mean horizontal speed over ``PUSH_OFF_WINDOW`` about the scenario's
  ``push_off.judged_at``;
- ``controller_update_ms``: median and p99 of the controller's update time.

Both RMSEs are taken over the samples from the scenario's ``metrics_start`` until the
end of the run (or the fall).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ridempc.robots.robot import Robot
from ridempc.rotations import euler_of_quaternions
from ridempc.scenarios.scenario import PUSH_OFF_WINDOW, Scenario
from ridempc.sim.simulation import RunResult

__all__ = ["board_roll", "board_tilt", "run_metrics"]


def board_tilt(quaternions: np.ndarray) -> np.ndarray:
    """Angle between a body's z axis and the world's [rad], for (w, x, y, z) quaternions."""
    x, y = quaternions[..., 1], quaternions[..., 2]
    return np.arccos(np.clip(1.0 - 2.0 * (x**2 + y**2), -1.0, 1.0))


def board_roll(quaternions: np.ndarray) -> np.ndarray:
    """Roll about the body's own x axis [rad] (z-y-x Euler angles), for (w, x, y, z)."""
    return euler_of_quaternions(quaternions)[0]


def _lateral_spacing(positions: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Distance between two platforms across the rider's heading [m]."""
    delta = positions[:, 0, :2] - positions[:, 1, :2]
    return -np.sin(yaw) * delta[:, 0] + np.cos(yaw) * delta[:, 1]


def _tracks(scenario: Scenario, field: str) -> bool:
    """Whether the scenario commands ``field`` at all."""
    events = any(getattr(e, field) not in (None, 0.0) for e in scenario.commands)
    return events or any(w.field == field for w in scenario.waves)


def _rmse(error: np.ndarray) -> float | None:
    return float(np.sqrt(np.mean(error**2))) if error.size else None


def _estimator_errors(log: dict[str, np.ndarray]) -> dict[str, float | None]:
    """RMS norm of the estimate's base velocity and position errors [m/s], [m]."""
    rows = np.isfinite(log["estimate_base_velocity"]).all(axis=1)
    errors: dict[str, float | None] = {}
    for name, estimate, truth in (
        ("estimator_velocity_rmse", "estimate_base_velocity", "base_velocity"),
        ("estimator_position_rmse", "estimate_base_position", "base_position"),
    ):
        error = np.linalg.norm(log[estimate][rows] - log[truth][rows], axis=1)
        errors[name] = _rmse(error)
    return errors


def run_metrics(result: RunResult, scenario: Scenario, robot: Robot | None) -> dict[str, Any]:
    log = result.log
    if not log:
        return {}
    window = log["time"] >= scenario.metrics_start
    base = log["base_position"]
    metrics: dict[str, Any] = {
        "velocity_rmse": _rmse(log["forward_velocity"][window] - log["command_velocity"][window]),
        "yaw_rate_rmse": _rmse(log["yaw_rate"][window] - log["command_yaw_rate"][window]),
        "base_height_initial": float(base[0, 2]),
        "base_height_drift": float(base[-1, 2] - base[0, 2]),
        "distance_travelled": float(np.linalg.norm(base[-1, :2] - base[0, :2])),
    }
    if robot is not None and "motor_torque" in log:
        peak = np.abs(log["motor_torque"]).max(axis=0)
        limits = np.array([m.torque_limit for m in robot.motors])
        metrics["peak_torque"] = {
            m.name: round(float(p), 3) for m, p in zip(robot.motors, peak, strict=True)
        }
        metrics["peak_torque_ratio"] = float(np.max(peak / limits))
    if robot is not None and "motor_demand" in log:
        # where the torque-speed curve cut what the PD and feedforward asked for
        cut = np.abs(log["motor_demand"]) > log["motor_available"] + 1e-9
        metrics["curve_limited_share"] = {
            m.name: round(float(s), 4) for m, s in zip(robot.motors, cut.mean(axis=0), strict=True)
        }
        metrics["curve_limited_share_max"] = float(cut.mean(axis=0).max())
    if "board_quaternion" in log and _tracks(scenario, "roll"):
        roll = board_roll(log["board_quaternion"][:, 0])
        metrics["roll_rmse"] = _rmse(roll[window] - log["command_roll"][window])
    if "board_position" in log and log["board_position"].shape[1] == 2:
        spacing = _lateral_spacing(log["board_position"], log["yaw"])
        wanted = spacing[0] + 2.0 * log["command_lateral_offset"]
        metrics["foot_spacing_rmse"] = _rmse(spacing[window] - wanted[window])
    if "board_quaternion" in log:
        metrics["board_max_tilt"] = float(np.max(board_tilt(log["board_quaternion"])))
        metrics["board_max_speed"] = float(
            np.max(np.linalg.norm(log["board_velocity"][..., :2], axis=-1))
        )
    if scenario.push_off is not None and "board_velocity" in log:
        push_off = scenario.push_off
        judged = np.abs(log["time"] - push_off.judged_at) <= 0.5 * PUSH_OFF_WINDOW
        speed = np.linalg.norm(log["board_velocity"][:, 0, :2], axis=-1)
        metrics["target_velocity"] = push_off.target
        metrics["final_velocity"] = float(np.mean(speed[judged])) if judged.any() else None
    if "estimate_base_velocity" in log:
        metrics.update(_estimator_errors(log))
    if result.controller_times.size:
        ms = 1e3 * result.controller_times
        metrics["controller_update_ms"] = {
            "median": float(np.median(ms)),
            "p99": float(np.percentile(ms, 99)),
        }
    return metrics
