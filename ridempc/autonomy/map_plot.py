"""``map.png``: the occupancy map, the true boxes, the planned and the ridden paths."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.course import Box
from ridempc.autonomy.occupancy import OccupancyGrid
from ridempc.io import atomic_savefig

__all__ = ["plot_map"]

Array = NDArray[np.float64]


def plot_map(
    path: Path,
    grid: OccupancyGrid,
    boxes: tuple[Box, ...],
    planned: list[Array],
    ridden: Array,
    estimated: Array,
    goal: Array,
    title: str,
) -> None:
    """Write the map figure to ``path`` (atomically)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    frame = grid.frame
    extent = (
        frame.origin[0],
        frame.origin[0] + frame.shape[0] * frame.resolution,
        frame.origin[1],
        frame.origin[1] + frame.shape[1] * frame.resolution,
    )
    shown = np.where(grid.observed, grid.probability(), np.nan)
    fig, ax = plt.subplots(figsize=(10, 10 * frame.shape[1] / frame.shape[0] + 1.0))
    image = ax.imshow(shown.T, origin="lower", extent=extent, cmap="Greys", vmin=0.0, vmax=1.0)
    fig.colorbar(image, ax=ax, shrink=0.6, label="occupancy probability (blank: unseen)")
    for i, box in enumerate(boxes):
        ax.add_patch(
            Polygon(
                box.corners(),
                closed=True,
                fill=False,
                ec="tab:orange",
                lw=1.5,
                label="true boxes" if i == 0 else None,
            )
        )
    for k, plan in enumerate(planned):
        ax.plot(
            plan[:, 0],
            plan[:, 1],
            color="tab:blue",
            lw=0.8,
            alpha=0.25 + 0.75 * (k == len(planned) - 1),
            label="global plans (last solid)" if k == len(planned) - 1 else None,
        )
    if len(estimated):
        ax.plot(
            estimated[:, 0],
            estimated[:, 1],
            "--",
            color="tab:purple",
            lw=1.0,
            label="estimated path",
        )
    ax.plot(ridden[:, 0], ridden[:, 1], color="tab:green", lw=2.0, label="ridden path (true)")
    ax.plot(*ridden[0], "o", color="tab:green")
    ax.plot(*goal, "*", color="tab:red", ms=14, label="goal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=8)
    atomic_savefig(fig, path, dpi=110)
    plt.close(fig)
