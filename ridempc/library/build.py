"""Building a pair's motion library: solve each entry, validate it, store it.

Every target is checked against the pair's feasibility bound before anything is solved (an
unreachable target is refused, nothing is written). Entries are then solved in worker
processes (``jobs`` of them, one process even when ``jobs`` is 1: CasADi holds Python's
interpreter lock while it builds a problem, so only a parent that merely waits can stop
within a second of Ctrl-C), in order of kind and
target, each warm-started from the nearest entry of its kind already solved in this build
(the lowest target of each kind starts cold, so a rebuild of it is reproducible). A solved
entry is re-simulated (:mod:`ridempc.trajopt.validation`), written atomically and added to
the manifest, which is rewritten after each entry; an entry IPOPT does not solve to
``Solve_Succeeded`` is reported and not written. Entries of the existing manifest that were
not rebuilt are kept.
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ridempc.errors import ConfigError, RidempcError
from ridempc.interrupts import stop_workers, worker_started
from ridempc.library.format import SUCCESS, EntryRecord
from ridempc.library.store import library_folder, read_manifest, store_entry, write_manifest
from ridempc.trajopt.pairs import EntrySpec, Neighbour, load_pair
from ridempc.trajopt.problem import solve_trajectory
from ridempc.trajopt.validation import resimulate

__all__ = ["BuildReport", "EntryOutcome", "build_library", "solve_entry"]


@dataclass(frozen=True)
class EntryOutcome:
    """What happened to one entry.

    Attributes:
        spec: The entry.
        status: IPOPT's return status, or the error's class name.
        iterations: IPOPT iterations.
        solve_time: Wall time in IPOPT [s].
        build_time: Wall time building the NLP and the solver [s].
        record: The stored record, or None when the entry was not stored.
        error: Why it was not stored.
    """

    spec: EntrySpec
    status: str
    iterations: int
    solve_time: float
    build_time: float
    record: EntryRecord | None
    error: str | None


@dataclass(frozen=True)
class BuildReport:
    """The outcome of a build: the library folder and one outcome per entry."""

    folder: Path
    outcomes: tuple[EntryOutcome, ...]

    @property
    def failed(self) -> tuple[EntryOutcome, ...]:
        return tuple(o for o in self.outcomes if o.record is None)


def solve_entry(
    robot: str, board: str, spec: EntrySpec, neighbour: Neighbour | None
) -> dict[str, Any]:
    """Build, solve and re-simulate one entry (runs in a worker process).

    Returns:
        Plain data: the record's fields and the arrays, or ``error`` with the reason.
    """
    pair = load_pair(robot, board)
    try:
        problem = pair.build(spec)
        guess = pair.guess(problem, neighbour)
        solution = solve_trajectory(problem, guess.states, guess.inputs, guess.midpoints)
    except (RidempcError, RuntimeError) as exc:  # RuntimeError: CasADi's own failures
        return {
            "status": type(exc).__name__,
            "error": str(exc),
            "iterations": 0,
            "solve_time": 0.0,
            "build_time": 0.0,
        }
    result: dict[str, Any] = {
        "status": solution.status,
        "iterations": solution.iterations,
        "solve_time": solution.solve_time,
        "build_time": solution.build_time,
        "error": None,
    }
    if solution.status != SUCCESS:
        result["error"] = f"IPOPT returned {solution.status} after {solution.iterations} iterations"
        return result
    drift = resimulate(
        problem.rates,
        problem.times,
        solution.states,
        solution.inputs,
        problem.parameters,
        pair.board_states(),
        problem.state_names,
    )
    result["record"] = {
        "name": spec.name,
        "kind": spec.kind,
        "target": spec.target,
        "status": solution.status,
        "iterations": solution.iterations,
        "solve_time_s": round(solution.solve_time, 3),
        "build_time_s": round(solution.build_time, 3),
        "max_violation": solution.max_violation,
        "n_intervals": problem.n_intervals,
        "dt": problem.dt,
        "nx": problem.nx,
        "nu": problem.nu,
        "n_parameters": int(problem.parameters.shape[1]),
        "drift": dataclasses.asdict(drift),
        "warm_start": neighbour.name if neighbour is not None else None,
        "metadata": {
            **problem.metadata,
            "timing_s": solution.timing,
            "entry_options": spec.options,
        },
    }
    result["arrays"] = {
        "times": problem.times,
        "states": solution.states,
        "inputs": solution.inputs,
        "midpoints": solution.midpoints,
        "parameters": problem.parameters,
        "state_names": np.array(problem.state_names),
        "input_names": np.array(problem.input_names),
    }
    result["neighbour"] = Neighbour(
        spec.name, problem.times, solution.states, solution.inputs, problem.metadata
    )
    return result


def _progress(total: int, enabled: bool) -> Any:
    try:
        from tqdm import tqdm
    except ImportError:  # the build still works, without a bar
        return None
    return tqdm(total=total, unit="entry", disable=not enabled, file=sys.stderr, leave=True)


def build_library(
    robot: str,
    board: str,
    targets: Sequence[float] | None = None,
    jobs: int = 1,
    out: Path | None = None,
    progress: bool = True,
    options: dict[str, Any] | None = None,
) -> BuildReport:
    """Build (or extend) the motion library of one robot-board pair.

    Args:
        robot: Robot name.
        board: Board name.
        targets: Target values (default: the pair's default targets).
        jobs: Worker processes.
        out: Library folder (default ``motion_library/<robot>-<board>``).
        progress: Show a progress bar on standard error.
        options: Overrides of the pair's problem options, for every entry.

    Raises:
        UnknownNameError: No trajectory optimisation for that pair.
        ConfigError: A target is unreachable, or ``jobs`` is not positive, or the existing
            manifest in ``out`` is corrupt (nothing is solved).
    """
    pair = load_pair(robot, board)
    if jobs < 1:
        raise ConfigError(f"--jobs must be at least 1, got {jobs}")
    folder = out or library_folder(robot, board)
    specs = pair.entries(pair.default_targets if targets is None else targets)
    specs = [dataclasses.replace(s, options={**s.options, **(options or {})}) for s in specs]
    for spec in specs:
        pair.check(spec)
    specs.sort(key=lambda s: (s.kind, s.target))
    kept: dict[str, EntryRecord] = {}
    if (folder / "manifest.json").exists():
        manifest = read_manifest(folder)
        if (manifest.robot, manifest.board) != (robot, board):
            raise ConfigError(
                f"{folder / 'manifest.json'}: holds {manifest.robot}-{manifest.board}, "
                f"not {robot}-{board}"
            )
        kept = {e.name: e for e in manifest.entries}

    solved: dict[str, Neighbour] = {}
    outcomes: list[EntryOutcome] = []
    pending = list(specs)
    running: dict[Future[dict[str, Any]], EntrySpec] = {}
    bar = _progress(len(specs), progress)
    executor = ProcessPoolExecutor(max_workers=jobs, initializer=worker_started)

    def neighbour_of(spec: EntrySpec) -> Neighbour | None:
        same = [n for n in solved.values() if n.metadata.get("kind") == spec.kind]
        if not same:
            return None
        return min(same, key=lambda n: abs(float(n.metadata["target"]) - spec.target))

    try:
        while pending or running:
            while pending and len(running) < jobs:
                spec = pending.pop(0)
                future = executor.submit(solve_entry, robot, board, spec, neighbour_of(spec))
                running[future] = spec
            done, _ = wait(list(running), return_when=FIRST_COMPLETED)
            for future in done:
                spec = running.pop(future)
                result = future.result()
                record = None
                if result["error"] is None:
                    record = store_entry(folder, result["record"], result["arrays"])
                    kept[record.name] = record
                    write_manifest(folder, robot, board, list(kept.values()))
                    solved[spec.name] = result["neighbour"]
                outcomes.append(
                    EntryOutcome(
                        spec=spec,
                        status=result["status"],
                        iterations=result["iterations"],
                        solve_time=result["solve_time"],
                        build_time=result["build_time"],
                        record=record,
                        error=result["error"],
                    )
                )
                if bar is not None:
                    bar.set_postfix_str(f"{spec.name}: {result['status']}")
                    bar.update(1)
    except BaseException:  # an interrupt or an error: the solves under way are not waited for
        stop_workers(executor)
        if bar is not None:
            bar.leave = False  # the command's own line says what happened
        raise
    finally:
        executor.shutdown(cancel_futures=True)
        if bar is not None:
            bar.close()
    outcomes.sort(key=lambda o: (o.spec.kind, o.spec.target))
    return BuildReport(folder=folder, outcomes=tuple(outcomes))
