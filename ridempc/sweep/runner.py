"""Ride many tasks on an engine, each recorded as one summary file once it has ended.

The one mechanism for riding many variants: ``ridempc sweep`` (drawn variants) and
``ridempc compare`` (one scenario, seeds ``0 .. N-1``) both hand their rides here.

- A ride's summary is written atomically (:mod:`ridempc.io`) by this process when the ride
  has ended, so a summary file is a whole ride: a ride interrupted or lost with its worker
  leaves none, and a run started again rides only the tasks whose file is missing.
- A ride that raises is recorded with ``status: failed`` and its error; the others go on.
- A worker that dies (killed, out of memory) is replaced (:meth:`Engine.replace`) and the
  rides it may have been riding are submitted again, each alone on the engine (a broken
  pool does not say whose worker died); one whose worker died :data:`MAX_ATTEMPTS` times
  is recorded as failed.
- Each summary carries the worker's peak resident memory, ``worker_peak_rss_mib`` [MiB].
"""

from __future__ import annotations

import json
import resource
import sys
from collections import Counter, deque
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from ridempc.io import atomic_write_json

if TYPE_CHECKING:
    from ridempc.scenarios import Scenario
    from ridempc.sweep.engines import Engine

__all__ = [
    "MAX_ATTEMPTS",
    "POLL_S",
    "RideListener",
    "RideTask",
    "failed_summary",
    "peak_rss_mib",
    "read_summary",
    "ride_task",
    "run_rides",
]

# Tries of a ride whose worker dies under it: once is chance (another ride's worker, the
# machine's memory), three times is the ride.
MAX_ATTEMPTS: int = 3
# [s] the longest the main thread waits for a ride without running Python: a SIGINT taken
# by a thread that does not block it (OpenBLAS's, started when NumPy was imported, before
# the command blocked the signals) raises the interrupt in the main thread only then.
POLL_S: float = 0.1
# ru_maxrss is in KiB on Linux and in bytes on macOS.
_RSS_UNIT: int = 1 if sys.platform == "darwin" else 1024


class RideListener(Protocol):
    """Told of each ride as it ends (a progress bar, a line per ride)."""

    def update(self, summary: Mapping[str, Any]) -> None: ...


@dataclass(frozen=True)
class RideTask:
    """One ride of a sweep.

    Attributes:
        variant: The variant's id (``v0000``; ``seed-3`` in a comparison).
        controller: Controller name.
        robot: Robot name.
        board: Board name.
        scenario: The scenario ridden (a variant's, with its drawn changes).
        seed: The ride's seed (sensor noise).
        summary_path: Where the summary is recorded.
        out: The ride's own output folder (``ridempc sim --out``: its ``log.npz``), or None
            to write nothing but the summary.
        duration: Override of the scenario's duration [s], or None.
    """

    variant: str
    controller: str
    robot: str
    board: str
    scenario: Scenario
    seed: int
    summary_path: Path
    out: Path | None = None
    duration: float | None = None


def peak_rss_mib() -> float:
    """This process's peak resident memory so far [MiB]."""
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * _RSS_UNIT / 2**20, 1)


def failed_summary(task: RideTask, error: str) -> dict[str, Any]:
    """The summary of a ride that raised, or whose worker kept dying."""
    return {
        "robot": task.robot,
        "board": task.board,
        "controller": task.controller,
        "scenario": task.scenario.name,
        "seed": task.seed,
        "status": "failed",
        "error": error,
        "fell": False,
        "fall_time_s": None,
        "fall_reason": None,
    }


def ride_task(task: RideTask) -> dict[str, Any]:
    """Ride one task through :func:`ridempc.api.ride` (in a worker); its summary.

    Anything the ride raises but an interrupt becomes a failed summary naming the error.
    """
    from ridempc.api import ride

    try:
        summary = ride(
            task.robot,
            task.board,
            task.controller,
            task.scenario,
            seed=task.seed,
            out=task.out,
            duration=task.duration,
        )
    except Exception as exc:  # a crashing ride is a result; an interrupt is not caught
        summary = failed_summary(task, f"{type(exc).__name__}: {exc}")
    summary["worker_peak_rss_mib"] = peak_rss_mib()
    return summary


def read_summary(path: Path) -> dict[str, Any] | None:
    """A recorded summary, or None where there is none (or an unreadable one: redone)."""
    try:
        summary = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) else None


def run_rides(
    tasks: Sequence[RideTask],
    engine: Engine,
    progress: RideListener | None = None,
    ride: Callable[[RideTask], dict[str, Any]] = ride_task,
) -> dict[tuple[str, str], dict[str, Any]]:
    """Ride every task whose summary file is missing; every task's summary.

    Args:
        tasks: The rides.
        engine: Where they run; stopped at once on an interrupt or an error, else left
            open (the caller closes it).
        progress: Told of each ride that ends.
        ride: The function a worker runs per task (a picklable, module-level function).

    Returns:
        Each task's summary by ``(variant, controller)``, the recorded ones included.

    Raises:
        Interrupted: A signal; the rides recorded so far are whole files, the rest absent.
        WriteFailed: A summary could not be written.
    """
    summaries: dict[tuple[str, str], dict[str, Any]] = {}
    pending: deque[RideTask] = deque()
    for task in tasks:
        recorded = read_summary(task.summary_path)
        if recorded is None:
            pending.append(task)
        else:
            summaries[(task.variant, task.controller)] = recorded
    attempts: Counter[tuple[str, str]] = Counter()
    running: dict[Future[dict[str, Any]], RideTask] = {}

    def suspect(task: RideTask) -> bool:
        return attempts[(task.variant, task.controller)] > 0

    def record(task: RideTask, summary: dict[str, Any]) -> None:
        atomic_write_json(task.summary_path, summary)
        summaries[(task.variant, task.controller)] = summary
        if progress is not None:
            progress.update(summary)

    def lost(interrupted: list[RideTask]) -> None:
        """The worker died: the rides under way go again, or are failed at the last try."""
        for task in reversed(interrupted):
            key = (task.variant, task.controller)
            attempts[key] += 1
            if attempts[key] >= MAX_ATTEMPTS:
                record(task, failed_summary(task, f"its worker died {MAX_ATTEMPTS} times"))
            else:
                pending.appendleft(task)
        engine.replace()

    try:
        while pending or running:
            try:
                while pending and len(running) < engine.slots:
                    if running and (suspect(pending[0]) or any(map(suspect, running.values()))):
                        break  # a ride under which a worker died rides alone: if it dies
                    task = pending.popleft()  # again, it is the one that kills its worker
                    running[engine.submit(ride, task)] = task
            except engine.broken:
                lost([task, *running.values()])
                running.clear()
                continue
            done, _ = wait(list(running), timeout=POLL_S, return_when=FIRST_COMPLETED)
            dead: list[RideTask] = []
            for future in done:
                task = running.pop(future)
                try:
                    summary = future.result()
                except engine.broken:
                    dead.append(task)
                    continue
                except Exception as exc:  # not picklable, a worker Dask gave up on
                    summary = failed_summary(task, f"{type(exc).__name__}: {exc}")
                record(task, summary)
            if dead:  # every ride under way was lost with the pool
                dead += running.values()
                running.clear()
                lost(dead)
    except BaseException:
        engine.stop()
        raise
    return summaries
