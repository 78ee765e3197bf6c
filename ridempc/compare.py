"""``ridempc compare``: two controllers on the same scenario and seeds, side by side.

Each controller rides the scenario once per seed (seeds ``0 .. N-1``) through
:func:`ridempc.run.ride`, exactly as ``ridempc sim`` would, into
``<out>/<controller>/seed-<k>/``. The figures come from each run's ``summary.json`` (the
judge's metrics, computed from the true state, never from a controller's view):

- survival: rides that ended without a fall or failure, out of N;
- every scalar metric both controllers report (velocity, yaw-rate, roll and foot-spacing
  RMSEs, peak torque ratio, estimator errors), as the mean over the seeds;
- the controller's update time, median and p99 [ms] over all ticks of all seeds, and the
  MPC's QP solve, whole MPC tick and WBC solve times when the controller reports them.

The table is printed and written as ``comparison.md`` and ``comparison.json``; the overlay
plot ``overlay.png`` shows seed 0 of each controller against the command (forward speed,
yaw rate, and the deck's roll where a roll is commanded). Files are written atomically, the
JSON last; the files of an earlier comparison in the same folder are removed first.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ridempc.checks import writable_dir
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.io import atomic_savefig, atomic_write_json, atomic_write_text
from ridempc.options import MAX_SEEDS
from ridempc.results import check_clearable, clear_results
from ridempc.run import RideRequest, check_request
from ridempc.scenarios import resolve_scenario
from ridempc.sweep.engines import LocalEngine
from ridempc.sweep.runner import RideTask, run_rides

__all__ = ["COMPARED_METRICS", "ComparisonRow", "compare", "comparison_table"]

# Scalar summary metrics compared, with their units, in table order.
COMPARED_METRICS: dict[str, str] = {
    "velocity_rmse": "m/s",
    "yaw_rate_rmse": "rad/s",
    "roll_rmse": "rad",
    "foot_spacing_rmse": "m",
    "final_velocity": "m/s",
    "peak_torque_ratio": "-",
    "estimator_velocity_rmse": "m/s",
    "board_max_tilt": "rad",
}
# Timing entries of the summary (each a {"median", "p99"} pair in ms).
TIMINGS: tuple[str, ...] = (
    "controller_update_ms",
    "mpc_solve_ms",
    "mpc_tick_ms",
    "wbc_solve_ms",
)


@dataclass(frozen=True)
class ComparisonRow:
    """One controller's figures over the seeds.

    Attributes:
        controller: Controller name.
        survived: Rides without a fall or failure.
        seeds: Rides run.
        metrics: Mean over the seeds of each reported scalar metric (NaN if none reported).
        timings: Median and p99 over the seeds of each reported timing [ms].
        summaries: The runs' summaries, seed order.
    """

    controller: str
    survived: int
    seeds: int
    metrics: dict[str, float]
    timings: dict[str, dict[str, float]]
    summaries: tuple[dict[str, Any], ...]


def _row(controller: str, summaries: list[dict[str, Any]]) -> ComparisonRow:
    survived = sum(1 for s in summaries if s["status"] == "ok" and not s["fell"])
    metrics = {}
    for name in COMPARED_METRICS:
        values = [float(s[name]) for s in summaries if s.get(name) is not None]
        metrics[name] = float(np.mean(values)) if values else float("nan")
    timings = {}
    for name in TIMINGS:
        reported = [s[name] for s in summaries if isinstance(s.get(name), dict)]
        if reported:
            timings[name] = {
                "median": float(np.median([t["median"] for t in reported])),
                "p99": float(np.max([t["p99"] for t in reported])),
            }
    return ComparisonRow(controller, survived, len(summaries), metrics, timings, tuple(summaries))


def comparison_table(rows: Sequence[ComparisonRow]) -> str:
    """A Markdown table, one column per controller; a metric no controller reports is left
    out."""
    header = "| figure | " + " | ".join(r.controller for r in rows) + " |"
    lines = [header, "|---" * (len(rows) + 1) + "|"]
    lines.append("| survived | " + " | ".join(f"{r.survived}/{r.seeds}" for r in rows) + " |")
    for name, unit in COMPARED_METRICS.items():
        values = [r.metrics[name] for r in rows]
        if all(np.isnan(v) for v in values):
            continue
        cells = " | ".join("-" if np.isnan(v) else f"{v:.4g}" for v in values)
        lines.append(f"| {name} [{unit}] | {cells} |")
    for name in TIMINGS:
        if not any(name in r.timings for r in rows):
            continue
        cells = " | ".join(
            f"{r.timings[name]['median']:.3g} / {r.timings[name]['p99']:.3g}"
            if name in r.timings
            else "-"
            for r in rows
        )
        lines.append(f"| {name} median / p99 | {cells} |")
    return "\n".join(lines)


def _overlay(out: Path, rows: Sequence[ComparisonRow], title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ridempc.sim.metrics import board_roll

    logs = {
        r.controller: np.load(out / r.controller / "seed-0" / "log.npz")
        for r in rows
        if (out / r.controller / "seed-0" / "log.npz").exists()  # (none if the ride raised)
    }
    if not logs:
        return
    first = next(iter(logs.values()))
    rolled = "command_roll" in first and np.any(first["command_roll"] != 0.0)
    panels = ["forward_velocity", "yaw_rate"] + (["roll"] if rolled else [])
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 2.6 * len(panels)), sharex=True)
    for ax, panel in zip(np.atleast_1d(axes), panels, strict=True):
        command = {"forward_velocity": "command_velocity", "yaw_rate": "command_yaw_rate"}
        for controller, log in logs.items():
            if panel == "roll":
                values = board_roll(log["board_quaternion"][:, 0])
            else:
                values = log[panel]
            ax.plot(log["time"], values, label=controller, lw=1.2)
        key = "command_roll" if panel == "roll" else command[panel]
        ax.plot(first["time"], first[key], "k--", lw=1.0, label="command")
        unit = {"forward_velocity": "m/s", "yaw_rate": "rad/s", "roll": "rad"}[panel]
        ax.set_ylabel(f"{panel} [{unit}]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    fig.tight_layout()
    try:
        atomic_savefig(fig, out / "overlay.png", dpi=110)
    finally:
        plt.close(fig)


class _Printer:
    """One line per ride as it ends."""

    def update(self, summary: Mapping[str, Any]) -> None:
        print(
            f"  {summary['controller']} seed {summary['seed']}: {summary['status']}"
            + (f", fell at {summary['fall_time_s']:.2f} s" if summary["fell"] else ""),
            flush=True,
        )


def compare(
    robot: str,
    board: str,
    scenario: str,
    out: Path,
    seeds: int = 1,
    controllers: Sequence[str] = ("pd", "mpc"),
    duration: float | None = None,
    workers: int = 1,
) -> list[ComparisonRow]:
    """Ride ``scenario`` with each controller for seeds ``0 .. seeds-1`` and compare.

    Everything is checked before the first ride (the output folder, each controller on the
    pair, the scenario on its scene); then every file an earlier run wrote in ``out`` is
    removed (:func:`~ridempc.results.clear_results`), so the folder never mixes two runs.

    Args:
        robot: Robot name.
        board: Board name.
        scenario: Scenario name or file.
        out: Output folder.
        seeds: Number of seeds (at least 1).
        controllers: Controllers to compare (names from ``ridempc list``).
        duration: Override of the scenario's duration [s].
        workers: Rides at once, each in its own worker process.

    Returns:
        One row per controller, in the given order.

    Raises:
        ConfigError: Seeds out of range, fewer than two controllers, a controller that does
            not ride the pair, a scenario that does not apply, an unwritable ``out``.
        UnknownNameError: A name that does not exist (before anything runs).
    """
    out = writable_dir(Path(out), "--out folder")
    check_clearable(out)
    if not 1 <= seeds <= MAX_SEEDS:
        raise ConfigError(f"--seeds {seeds}: allowed: a whole number in [1, {MAX_SEEDS}]")
    if len(controllers) < 2 or len(set(controllers)) != len(controllers):
        raise ConfigError(f"compare needs two different controllers, got {list(controllers)}")
    from ridempc.controllers import controller_names

    for controller in controllers:
        if controller not in controller_names():
            raise UnknownNameError("controller", controller, controller_names())

    def request(controller: str, seed: int) -> RideRequest:
        return RideRequest(
            robot=robot,
            board=board,
            controller=controller,
            scenario=scenario,
            out=out / controller / f"seed-{seed}",
            duration=duration,
            seed=seed,
            plots=False,
        )

    for controller in controllers:  # every controller, pair and scenario before any ride
        check_request(request(controller, 0))
    ridden = resolve_scenario(scenario, board)
    tasks = [
        RideTask(
            variant=f"seed-{seed}",  # the unmodified scenario, one variant per seed
            controller=controller,
            robot=robot,
            board=board,
            scenario=ridden,
            seed=seed,
            summary_path=out / controller / f"seed-{seed}" / "summary.json",
            out=out / controller / f"seed-{seed}",
            duration=duration,
        )
        for controller in controllers
        for seed in range(seeds)
    ]
    engine = LocalEngine(workers)  # a pool even of one: a ride that kills its worker is redone
    clear_results(out)
    try:
        summaries = run_rides(tasks, engine, _Printer())
    finally:
        engine.close()
    rows = [_row(c, [summaries[(f"seed-{seed}", c)] for seed in range(seeds)]) for c in controllers]
    title = f"{robot} / {board} / {rows[0].summaries[0]['scenario']} ({seeds} seed(s))"
    table = comparison_table(rows)
    atomic_write_text(out / "comparison.md", f"# {title}\n\n{table}\n")
    _overlay(out, rows, title)
    atomic_write_json(
        out / "comparison.json",
        {
            "robot": robot,
            "board": board,
            "scenario": rows[0].summaries[0]["scenario"],
            "seeds": seeds,
            "controllers": {
                r.controller: {
                    "survived": r.survived,
                    "seeds": r.seeds,
                    "metrics": {k: (None if np.isnan(v) else v) for k, v in r.metrics.items()},
                    "timings": r.timings,
                }
                for r in rows
            },
        },
    )
    print(table)
    return rows
