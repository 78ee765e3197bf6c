"""PNG plots of a run's log: base height, speed and yaw rate against their commands, torques."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ridempc.robots.robot import Robot

__all__ = ["plot_run"]


def plot_run(log: dict[str, np.ndarray], robot: Robot, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = log["time"]
    fig, axes = plt.subplots(4, 1, figsize=(9, 10), sharex=True)
    axes[0].plot(t, log["base_position"][:, 2])
    axes[0].axhline(robot.params.fall_height, color="r", ls="--", lw=0.8, label="fall height")
    axes[0].set_ylabel("base height [m]")
    axes[0].legend(loc="lower right")
    axes[1].plot(t, log["forward_velocity"], label="measured (true)")
    axes[1].plot(t, log["command_velocity"], "k--", label="command")
    axes[1].set_ylabel("forward speed [m/s]")
    axes[1].legend(loc="upper right")
    axes[2].plot(t, log["yaw_rate"], label="measured (true)")
    axes[2].plot(t, log["command_yaw_rate"], "k--", label="command")
    axes[2].set_ylabel("yaw rate [rad/s]")
    axes[2].legend(loc="upper right")
    for i, motor in enumerate(robot.motors):
        axes[3].plot(t, log["motor_torque"][:, i], lw=0.8, label=motor.name)
    axes[3].set_ylabel("motor torque [N m]")
    axes[3].set_xlabel("time [s]")
    axes[3].legend(loc="upper right", fontsize=6, ncol=2)
    fig.suptitle(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=90)
    plt.close(fig)
    tmp.replace(path)
