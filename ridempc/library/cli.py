"""``ridempc library build`` and ``ridempc library show``.

Bad input (an unknown pair, an unreachable or malformed target, a corrupt or tampered library)
raises :class:`~ridempc.errors.ConfigError` or :class:`~ridempc.errors.UnknownNameError`,
which the command turns into one line and exit code 2; entries IPOPT fails to solve are
reported one line each on standard error, left out, and the command exits with 1.
"""

from __future__ import annotations

import sys
from pathlib import Path

from ridempc.checks import readable_dir, writable_dir, writable_file
from ridempc.errors import ConfigError
from ridempc.library.build import build_library
from ridempc.library.format import EntryRecord
from ridempc.library.store import LibraryEntry, library_folder, load_library
from ridempc.trajopt.pairs import load_pair

__all__ = ["library_build", "library_show", "parse_targets", "table"]

EXIT_FAILED = 1


def parse_targets(text: str | None) -> list[float] | None:
    """``"0.3,0.5"`` -> ``[0.3, 0.5]``; None stays None (the pair's defaults)."""
    if text is None:
        return None
    targets = []
    for part in text.split(","):
        try:
            value = float(part)
        except ValueError:
            raise ConfigError(f"--targets: '{part.strip()}' is not a number") from None
        if value != value or value in (float("inf"), float("-inf")):
            raise ConfigError(f"--targets: '{part.strip()}' is not a finite number")
        targets.append(value)
    if len(set(targets)) != len(targets):
        raise ConfigError(f"--targets: '{text}' repeats a target")
    return targets


def table(records: list[EntryRecord]) -> str:
    """The manifest as a text table."""
    lines = [
        f"{'entry':<18}{'target':>7}  {'status':<16}{'iter':>5}{'IPOPT [s]':>10}"
        f"{'build [s]':>10}{'max defect':>12}{'drift local':>12}{'drift board':>12}"
        f"{'N':>5}{'T [s]':>7}  warm start"
    ]
    for r in records:
        lines.append(
            f"{r.name:<18}{r.target:>7.2f}  {r.status:<16}{r.iterations:>5}"
            f"{r.solve_time_s:>10.2f}{r.build_time_s:>10.2f}{r.max_violation:>12.1e}"
            f"{r.drift.local:>12.1e}{r.drift.board:>12.1e}{r.n_intervals:>5}"
            f"{r.n_intervals * r.dt:>7.2f}  {r.warm_start or '-'}"
        )
    return "\n".join(lines)


def library_build(robot: str, board: str, targets: str | None, jobs: int, out: Path | None) -> int:
    folder = writable_dir(out or library_folder(robot, board), "library folder")
    report = build_library(robot, board, parse_targets(targets), jobs=jobs, out=folder)
    stored = [o.record for o in report.outcomes if o.record is not None]
    if stored:
        print(table(stored))
    for outcome in report.failed:
        print(
            f"ridempc: failed: entry '{outcome.spec.name}': {outcome.error}; not stored",
            file=sys.stderr,
        )
    print(f"{len(stored)} of {len(report.outcomes)} entries stored in {report.folder}")
    return EXIT_FAILED if report.failed else 0


def _find(entries: list[LibraryEntry], key: str, folder: Path) -> LibraryEntry:
    by_name = [e for e in entries if e.record.name == key]
    if by_name:
        return by_name[0]
    try:
        value = float(key)
    except ValueError:
        value = float("nan")
    matches = [e for e in entries if abs(e.record.target - value) < 1e-9]
    names = ", ".join(e.record.name for e in entries) or "none"
    if len(matches) == 1:
        return matches[0]
    if len(matches) > 1:
        raise ConfigError(
            f"--entry {key}: several entries have that target "
            f"({', '.join(e.record.name for e in matches)}); name one"
        )
    raise ConfigError(f"--entry {key}: no such entry in {folder} (valid: {names})")


def library_show(
    robot: str, board: str, folder: Path | None, entry: str | None, plot: Path | None
) -> int:
    pair = load_pair(robot, board)
    folder = readable_dir(folder or library_folder(robot, board), "library folder")
    if plot is not None and entry is None:
        raise ConfigError("--plot needs --entry (the entry to plot)")
    if plot is not None:
        if plot.suffix.lower() != ".png":
            raise ConfigError(f"--plot {plot}: allowed: a file name ending in .png")
        writable_file(plot, "--plot file")
    manifest, entries = load_library(folder)
    if (manifest.robot, manifest.board) != (robot, board):
        raise ConfigError(
            f"{folder / 'manifest.json'}: holds {manifest.robot}-{manifest.board}, "
            f"not {robot}-{board}"
        )
    chosen = None if entry is None else _find(entries, entry, folder)  # before any output
    print(f"{pair.name}: {len(entries)} entries in {folder} (all hashes and arrays verified)")
    print(table([e.record for e in entries]))
    if chosen is not None:
        r = chosen.record
        print(
            f"{r.name}: {r.n_intervals} intervals of {r.dt} s; drift: local {r.drift.local:.1e}, "
            f"board {r.drift.board:.1e}, open loop within tolerance for "
            f"{r.drift.open_loop_time:.2f} s ({r.drift.integrator})"
        )
        if plot is not None:
            from ridempc.library.plot import plot_entry

            plot_entry(chosen, plot, pair.name)
            print(f"plot written to {plot}")
    return 0
