"""The files ridempc writes into an ``--out`` folder, listed once, and their removal.

A run that starts in a folder an earlier run wrote removes every file that earlier run
wrote before it writes its own, so a folder never mixes two runs, whether the earlier one
was a ``sim`` or a ``compare``. It removes only the files listed here (and their temporary
files, left by a run that was killed): anything else in the folder, such as a user's notes,
is never touched, and a folder that is then empty is removed only where ridempc made it (a
compare's per-controller and per-seed folders).
"""

from __future__ import annotations

import re
from pathlib import Path

from ridempc.errors import ConfigError

__all__ = ["COMPARISON_FILES", "RUN_FILES", "check_clearable", "clear_results"]

# What ``ridempc sim`` writes (summary.json first: its absence marks an unfinished run).
RUN_FILES: tuple[str, ...] = (
    "summary.json",
    "log.npz",
    "plots.png",
    "video.mp4",
    "snapshots.png",
    "map.png",  # ridempc navigate
)
# What ``ridempc compare`` writes beside its ``<controller>/seed-<k>/`` run folders.
COMPARISON_FILES: tuple[str, ...] = ("comparison.json", "comparison.md", "overlay.png")

_SEED_FOLDER = re.compile(r"^seed-[0-9]+$")


def check_clearable(folder: Path) -> None:
    """Refuse a folder where a name ridempc writes is taken by something it cannot replace
    (a folder called ``log.npz``), before any work starts."""
    for name in (*RUN_FILES, *COMPARISON_FILES):
        taken = folder / name
        if taken.is_dir() and not taken.is_symlink():
            raise ConfigError(
                f"{taken}: a folder where ridempc writes its file '{name}'; "
                "allowed: an --out folder without it"
            )


def clear_results(folder: Path) -> None:
    """Remove what an earlier ``ridempc sim`` or ``ridempc compare`` wrote in ``folder``:
    its files and every ``<controller>/seed-<k>/`` run, whatever controllers and seeds it
    had (nothing if the folder is new)."""
    if not folder.is_dir():
        return
    _remove(folder, (*RUN_FILES, *COMPARISON_FILES))
    for controller in [p for p in folder.iterdir() if p.is_dir() and not p.is_symlink()]:
        seeds = [p for p in controller.iterdir() if p.is_dir() and _SEED_FOLDER.match(p.name)]
        for seed in seeds:
            _remove(seed, RUN_FILES)
            _remove_if_empty(seed)
        if seeds:
            _remove_if_empty(controller)


def _remove(folder: Path, names: tuple[str, ...]) -> None:
    for name in names:
        stale = [folder / name, *(p for p in folder.glob(f".{name}.*") if p.is_file())]
        for path in stale:  # the file and its temporary files, ".<name>.<...>"
            try:
                path.unlink(missing_ok=True)
            except OSError as exc:
                raise ConfigError(f"{path}: cannot remove an earlier run's file ({exc})") from exc


def _remove_if_empty(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:  # not empty: it holds files ridempc did not write
        pass
