"""The hottest functions of each part of the control tick (``ridempc bench --profile``).

One :mod:`cProfile` profiler per part of the closed loop's tick (the budget's parts of
:mod:`ridempc.bench`: the simulation, the estimator, the MPC's share in the loop's thread,
the whole-body controller and the rest of the rider), of which exactly one records at a
time: entering a part (:meth:`PartProfiler.wrap`) pauses the part it was called from and
records into its own until it returns. So each function's time lands in the part that
called it, whichever module it is in (NumPy's ``concatenate`` in the MPC's problem and in
the WBC's assembly are counted apart).

Each part's functions are ranked by their *own* time (``tottime``, without what they
call): a profiler paused inside a call cannot see its caller's cumulative time whole, and
the own time is what a change to that function can take away. The profiler's hooks slow
every Python call, so the times are the profiled ride's, larger than the bench's budget;
they rank the functions within a part, the budget says what each part costs.
"""

from __future__ import annotations

import cProfile
import pstats
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["DEFAULT_TOP", "PartProfiler", "profile_table"]

DEFAULT_TOP: int = 8  # functions listed per part: past the eighth, each holds a few percent


class PartProfiler:
    """One profiler per part, one recording at a time (module docstring).

    Args:
        parts: The parts' names; the first records whatever no wrapped call claims.
    """

    def __init__(self, parts: Sequence[str]) -> None:
        if not parts:
            raise ValueError("PartProfiler: at least one part")
        self.parts = tuple(parts)
        self._profiles = {part: cProfile.Profile() for part in self.parts}
        self._stack: list[str] = []

    def start(self) -> None:
        """Record into the first part (the loop's own) from now on."""
        self._enter(self.parts[0])

    def stop(self) -> None:
        """Stop recording (every part)."""
        while self._stack:
            self._leave()

    def _enter(self, part: str) -> None:
        if self._stack:
            self._profiles[self._stack[-1]].disable()
        self._stack.append(part)
        self._profiles[part].enable()

    def _leave(self) -> None:
        self._profiles[self._stack.pop()].disable()
        if self._stack:
            self._profiles[self._stack[-1]].enable()

    def wrap(self, function: Callable[..., Any], part: str) -> Callable[..., Any]:
        """``function``, recorded into ``part`` while it runs (the caller's part paused)."""
        if part not in self._profiles:
            raise ValueError(f"PartProfiler: unknown part '{part}' (valid: {self.parts})")

        def recorded(*args: Any, **kwargs: Any) -> Any:
            if not self._stack:  # not started, or stopped: not profiled
                return function(*args, **kwargs)
            self._enter(part)
            try:
                return function(*args, **kwargs)
            finally:
                self._leave()

        return recorded

    def hottest(self, ticks: int, top: int = DEFAULT_TOP) -> dict[str, list[dict[str, Any]]]:
        """Each part's ``top`` functions by own time, per control tick.

        Args:
            ticks: Control ticks the profiled ride took (the times' divisor).
            top: Functions listed per part.

        Returns:
            Per part, a list of ``function`` (``file:line(name)``, or ``{built-in}``),
            ``calls``, ``own_ms_per_tick`` and ``share`` (of the part's profiled own time).
        """
        out: dict[str, list[dict[str, Any]]] = {}
        per_tick = 1e3 / max(ticks, 1)
        for part, profile in self._profiles.items():
            try:
                stats = pstats.Stats(profile).stats  # type: ignore[attr-defined]
            except TypeError:  # nothing recorded in this part
                out[part] = []
                continue
            rows = sorted(stats.items(), key=lambda item: item[1][2], reverse=True)
            total = sum(row[2] for _, row in rows) or 1.0
            out[part] = [
                {
                    "function": _name(key),
                    "calls": int(row[1]),
                    "own_ms_per_tick": row[2] * per_tick,
                    "share": row[2] / total,
                }
                for key, row in rows[:top]
            ]
        return out


def _name(key: tuple[str, int, str]) -> str:
    """``file:line(function)`` with the path cut to the package, or a built-in's name."""
    file, line, function = key
    if file == "~" and line == 0:  # a built-in or a C method
        return function
    for root in ("/ridempc/", "/site-packages/"):
        if root in file:
            file = file.split(root, 1)[1]
            break
    return f"{file}:{line}({function})"


def profile_table(rows: Sequence[tuple[str, dict[str, list[dict[str, Any]]]]]) -> list[str]:
    """The profiles as Markdown lines: per pair and part, its hottest functions."""
    lines = [
        "",
        "| pair | part | function | calls | own time per tick [ms] (profiled) | share of part |",
        "|---|---|---|---|---|---|",
    ]
    for pair, parts in rows:
        for part, functions in parts.items():
            for f in functions:
                lines.append(
                    f"| {pair} | {part} | `{f['function']}` | {f['calls']} | "
                    f"{f['own_ms_per_tick']:.3f} | {100 * f['share']:.0f} % |"
                )
    return lines
