"""PNG plots of a run's log: base height, speed and yaw rate against their commands, torques,
the controller's state estimate against the truth (when it has one) and the board's tilt."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ridempc.io import atomic_savefig
from ridempc.robots.robot import Robot
from ridempc.rotations import euler_of_quaternions

__all__ = ["plot_run"]


def plot_run(log: dict[str, np.ndarray], robot: Robot | None, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = log["time"]
    board = "board_quaternion" in log
    estimate = "estimate_base_velocity" in log
    rows = 4 + board + estimate
    fig, axes = plt.subplots(rows, 1, figsize=(9, 2.5 * rows), sharex=True)
    axes[0].plot(t, log["base_position"][:, 2])
    axes[0].set_ylabel("rider base height [m]")
    axes[1].plot(t, log["forward_velocity"], label="measured (true)")
    axes[1].plot(t, log["command_velocity"], "k--", label="command")
    axes[1].set_ylabel("forward speed [m/s]")
    axes[1].legend(loc="upper right")
    axes[2].plot(t, log["yaw_rate"], label="measured (true)")
    axes[2].plot(t, log["command_yaw_rate"], "k--", label="command")
    axes[2].set_ylabel("yaw rate [rad/s]")
    axes[2].legend(loc="upper right")
    if robot is not None:
        for i, motor in enumerate(robot.motors):
            axes[3].plot(t, log["motor_torque"][:, i], lw=0.8, label=motor.name)
        axes[3].set_ylabel("motor torque [N m]")
        axes[3].legend(loc="upper right", fontsize=6, ncol=2)
    else:  # a dead weight: show what the board's firmware commands instead
        for key in sorted(k for k in log if k.startswith("firmware_") and k.endswith("torque")):
            axes[3].plot(t, log[key], lw=0.8, label=key.removeprefix("firmware_"))
        axes[3].set_ylabel("firmware wheel torque [N m]")
        if axes[3].lines:
            axes[3].legend(loc="upper right", fontsize=7)
        else:
            axes[3].text(
                0.5,
                0.5,
                "passive board: no firmware output",
                ha="center",
                transform=axes[3].transAxes,
            )
    if estimate:
        _plot_estimate(axes[4], t, log)
    if board:
        quat = log["board_quaternion"]
        roll, pitch, _ = euler_of_quaternions(quat)
        for i in range(quat.shape[1]):
            axes[-1].plot(t, np.degrees(pitch[:, i]), label=f"platform {i} pitch")
            axes[-1].plot(t, np.degrees(roll[:, i]), ls=":", label=f"platform {i} roll")
        axes[-1].set_ylabel("board tilt [deg]")
        axes[-1].legend(loc="upper right", fontsize=7, ncol=2)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    fig.tight_layout()
    try:
        atomic_savefig(fig, path, dpi=90)
    finally:
        plt.close(fig)


def _plot_estimate(ax, t: np.ndarray, log: dict[str, np.ndarray]) -> None:
    """The controller's estimate of the base velocity (dashed) against the truth (solid)."""
    truth, estimate = log["base_velocity"], log["estimate_base_velocity"]
    for i, (axis, colour) in enumerate(zip("xyz", ("C0", "C1", "C2"), strict=True)):
        ax.plot(t, truth[:, i], color=colour, lw=0.9, label=f"{axis} true")
        ax.plot(t, estimate[:, i], color=colour, lw=0.9, ls="--", label=f"{axis} estimate")
    rows = np.isfinite(estimate).all(axis=1)
    velocity = np.linalg.norm(estimate[rows] - truth[rows], axis=1)
    position = np.linalg.norm(
        log["estimate_base_position"][rows] - log["base_position"][rows], axis=1
    )
    if rows.any():
        ax.set_title(
            f"estimator error (RMS): velocity {np.sqrt(np.mean(velocity**2)):.3f} m/s, "
            f"position {np.sqrt(np.mean(position**2)):.3f} m",
            fontsize=8,
        )
    ax.set_ylabel("base velocity [m/s]")
    ax.legend(loc="upper right", fontsize=6, ncol=3)
