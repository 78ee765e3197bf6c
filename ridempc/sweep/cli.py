"""``ridempc sweep``: draw N variants of a scenario, ride each with every controller (paired),
and write the statistics and the report.

Everything is checked before the first ride (:func:`~ridempc.sweep.plan.plan_sweep`, then
the engine: one that is not installed, or an address where no scheduler answers, is one
line and exit code 2). The rides are recorded one file each as they end
(:mod:`ridempc.sweep.runner`); ``sweep.json``, ``report.md`` and ``report.html`` are
written once every ride is recorded, and a table is printed. Exit code 1 when a ride
failed (it is recorded, and the sweep went on), 0 otherwise, falls included.
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any

from ridempc import options

__all__ = ["add_parser", "run", "unwritten"]

EXIT_FAILED = 1


def add_parser(commands: Any) -> None:
    """Add ``sweep`` to the command line's sub-commands."""
    from ridempc.sweep.engines import ENGINES
    from ridempc.sweep.plan import MAX_SAMPLES

    sweep = commands.add_parser(
        "sweep", help="ride N drawn variants of a scenario with each controller, paired"
    )
    sweep.add_argument("--robot", required=True, help="robot name")
    sweep.add_argument("--board", required=True, help="board name")
    sweep.add_argument("--scenario", required=True, help="scenario name or .toml file")
    sweep.add_argument("--distribution", required=True, help="distribution name or .toml file")
    sweep.add_argument(
        "--samples",
        type=options.bounded_int(1, MAX_SAMPLES),
        required=True,
        help=f"variants drawn, in [1, {MAX_SAMPLES}]",
    )
    sweep.add_argument(
        "--controllers", default="pd,mpc", help="comma-separated controllers (default: pd,mpc)"
    )
    sweep.add_argument(
        "--seed",
        type=options.bounded_int(0, options.MAX_SEED),
        default=0,
        help="seed of the draws: the same seed, the same variants (default: 0)",
    )
    sweep.add_argument(
        "--workers",
        type=options.bounded_int(1, options.MAX_JOBS),
        default=os.cpu_count() or 1,
        help=f"worker processes, 1 to {options.MAX_JOBS} (default: this machine's cores; with "
        "--address, the cluster's own)",
    )
    sweep.add_argument("--engine", choices=ENGINES, default="local", help="local (default) or dask")
    sweep.add_argument(
        "--address", default=None, help="a running Dask scheduler (default: start a local one)"
    )
    sweep.add_argument(
        "--duration",
        type=options.duration,
        default=None,
        help="override the scenario's duration [s] (before the draws)",
    )
    sweep.add_argument(
        "--out",
        type=options.path,
        required=True,
        help="sweep folder; the same command again resumes it",
    )


def unwritten(args: argparse.Namespace) -> str:
    """What an interrupted sweep leaves undone, for the command's one line."""
    return (
        f"no sweep.json was written in {args.out}; the rides that ended are kept, and the "
        "same command again rides the rest"
    )


def run(args: argparse.Namespace) -> int:
    """Run ``ridempc sweep`` (module docstring); the exit code."""
    from ridempc.io import atomic_write_json
    from ridempc.sweep.aggregate import sweep_results
    from ridempc.sweep.engines import make_engine
    from ridempc.sweep.plan import parse_controllers, plan_sweep
    from ridempc.sweep.progress import Progress
    from ridempc.sweep.report import survival_table, write_report
    from ridempc.sweep.runner import read_summary, run_rides

    controllers = parse_controllers(args.controllers)
    plan = plan_sweep(
        args.robot,
        args.board,
        args.scenario,
        args.distribution,
        args.samples,
        controllers,
        args.seed,
        args.out,
        duration=args.duration,
    )
    engine = make_engine(args.engine, args.workers, args.address)
    try:
        layout = plan.layout
        layout.start(plan.manifest)
        for variant in plan.variants:
            layout.write_variant(variant["id"], variant["toml"])
        recorded = {
            (t.variant, t.controller): s
            for t in plan.tasks
            if (s := read_summary(t.summary_path)) is not None
        }
        done = list(recorded.values())
        progress = Progress(len(plan.tasks), controllers, done)
        started = time.perf_counter()
        finished = False
        try:
            summaries = run_rides(plan.tasks, engine, progress)
            finished = True
        finally:
            progress.close(finished)
        elapsed = time.perf_counter() - started
    except BaseException:  # an interrupt, an error: the rides under way are not waited for
        engine.stop()
        raise
    engine.close()
    results = sweep_results(plan.header(), plan.records(), controllers, summaries)
    write_report(results, layout.folder)
    atomic_write_json(layout.sweep_json, results)  # last: its presence says the sweep is whole
    print(survival_table(results))
    ridden = [s for key, s in summaries.items() if key not in recorded]
    print(_throughput(ridden, elapsed, engine.slots))
    print(f"results in {layout.folder} (report.md, report.html, sweep.json)")
    return EXIT_FAILED if results["failed"] else 0


def _throughput(ridden: list[dict[str, Any]], elapsed: float, slots: int) -> str:
    """Rides per hour, and the time per ride spent besides simulating (each ride's setup,
    a new worker's imports, the sweep's own work), over the rides of this run."""
    if not ridden:
        return "every ride was already recorded: nothing ridden"
    mean_ride = sum(float(s.get("wall_time_s") or 0.0) for s in ridden) / len(ridden)
    overhead = elapsed * min(slots, len(ridden)) / len(ridden) - mean_ride
    return (
        f"{len(ridden)} rides in {elapsed:.1f} s on {slots} worker(s): "
        f"{3600.0 * len(ridden) / elapsed:.0f} rides/h; {overhead:.2f} s per ride besides "
        f"simulating (mean simulation {mean_ride:.2f} s)"
    )
