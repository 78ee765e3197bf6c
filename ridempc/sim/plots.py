"""PNG plots of a run's log: base height, speed and yaw rate against their commands, torques."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ridempc.robots.robot import Robot

__all__ = ["plot_run"]


def plot_run(log: dict[str, np.ndarray], robot: Robot | None, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = log["time"]
    board = "board_quaternion" in log
    fig, axes = plt.subplots(5 if board else 4, 1, figsize=(9, 12 if board else 10), sharex=True)
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
    if board:
        quat = log["board_quaternion"]
        w, x, y, z = (quat[..., i] for i in range(4))
        pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
        roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x**2 + y**2))
        for i in range(quat.shape[1]):
            axes[-1].plot(t, np.degrees(pitch[:, i]), label=f"platform {i} pitch")
            axes[-1].plot(t, np.degrees(roll[:, i]), ls=":", label=f"platform {i} roll")
        axes[-1].set_ylabel("board tilt [deg]")
        axes[-1].legend(loc="upper right", fontsize=7, ncol=2)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=90)
    plt.close(fig)
    tmp.replace(path)
