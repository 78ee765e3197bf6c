"""A PNG of one library entry: the board's states, the rider's centre of mass, the inputs."""

from __future__ import annotations

from pathlib import Path

from ridempc.io import atomic_savefig
from ridempc.library.store import LibraryEntry

__all__ = ["plot_entry"]


def plot_entry(entry: LibraryEntry, path: Path, title: str) -> None:
    """Plot the board's states, the rider's centre of mass and every input against time,
    with the contact schedule's phases shaded (when the entry has one)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = entry.times
    names = entry.state_names
    board = [n for n in entry.record.metadata.get("board_states", []) if n in names]
    rider = [n for n in names if n.startswith("com_") or n in ("vx", "vy", "vz")]
    forces = [n for n in entry.input_names if n.startswith("f_")]
    others = [n for n in entry.input_names if n not in forces]
    panels = [p for p in (board, rider, forces, others) if p]
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 2.8 * len(panels)), sharex=True)
    axes = list(axes) if len(panels) > 1 else [axes]
    for ax, panel in zip(axes, panels, strict=True):
        for name in panel:
            if name in names:
                ax.plot(t, entry.state(name), label=name, lw=1.0)
            else:
                column = entry.input_names.index(name)
                ax.step(t[:-1], entry.inputs[:, column], where="post", label=name, lw=0.8)
        ax.legend(loc="upper left", fontsize=6, ncol=4)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("board [SI]")
    start = 0.0
    for phase in entry.record.metadata.get("phases", []):
        end = start + float(phase["duration"])
        if phase.get("mode") in ("push", "lean", "brake", "turn"):
            for ax in axes:
                ax.axvspan(start, end, color="orange", alpha=0.12, lw=0)
        start = end
    axes[-1].set_xlabel("time [s] (shaded: the active phase, e.g. the foot pushing)")
    r = entry.record
    fig.suptitle(
        f"{title}: {r.name}, {r.status}, {r.iterations} iterations, "
        f"{r.solve_time_s:.1f} s IPOPT, max defect {r.max_violation:.1e}"
    )
    fig.tight_layout()
    try:
        atomic_savefig(fig, Path(path), dpi=110)
    finally:
        plt.close(fig)
