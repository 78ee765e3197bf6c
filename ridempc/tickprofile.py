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

The same ride is also split by the *kind* of each control tick (``kinds``: the MPC's tick,
the plan's take-up, the backup's standby, the other steady ticks, :mod:`ridempc.tickphases`),
one profiler per kind and part: :meth:`PartProfiler.begin_tick` names the kind of the tick
that starts, :meth:`PartProfiler.wrap_kind` a call that is a kind of its own wherever it runs
(the MPC's build and solve). :meth:`PartProfiler.hottest` sums each part over the kinds,
:meth:`PartProfiler.hottest_by_kind` each kind over the controller's parts (all but the
first, the loop's own), per tick of that kind: where a periodic tick's time goes.
"""

from __future__ import annotations

import cProfile
import pstats
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["DEFAULT_TOP", "PartProfiler", "profile_table"]

DEFAULT_TOP: int = 8  # functions listed per part: past the eighth, each holds a few percent


class PartProfiler:
    """One profiler per part, one recording at a time (module docstring).

    Args:
        parts: The parts' names; the first records whatever no wrapped call claims.
        kinds: The kinds of tick (module docstring); the first is the one recorded into
            until :meth:`begin_tick` names another.
    """

    def __init__(self, parts: Sequence[str], kinds: Sequence[str] = ("tick",)) -> None:
        if not parts:
            raise ValueError("PartProfiler: at least one part")
        if not kinds:
            raise ValueError("PartProfiler: at least one kind of tick")
        self.parts, self.kinds = tuple(parts), tuple(kinds)
        self._profiles = {(k, p): cProfile.Profile() for k in self.kinds for p in self.parts}
        self._stack: list[str] = []
        self._kind = self.kinds[0]
        self._ticks: Counter[str] = Counter()  # ticks (or wrapped calls) of each kind

    def start(self) -> None:
        """Record into the first part (the loop's own) from now on."""
        self._enter(self.parts[0])

    def stop(self) -> None:
        """Stop recording (every part)."""
        while self._stack:
            self._leave()

    def _enter(self, part: str) -> None:
        if self._stack:
            self._profiles[self._kind, self._stack[-1]].disable()
        self._stack.append(part)
        self._profiles[self._kind, part].enable()

    def _leave(self) -> None:
        self._profiles[self._kind, self._stack.pop()].disable()
        if self._stack:
            self._profiles[self._kind, self._stack[-1]].enable()

    def _switch(self, kind: str) -> None:
        """Record into ``kind``'s profiles from now on, in the same part."""
        if kind not in self.kinds:
            raise ValueError(f"PartProfiler: unknown kind '{kind}' (valid: {self.kinds})")
        if self._stack:
            self._profiles[self._kind, self._stack[-1]].disable()
        self._kind = kind
        if self._stack:
            self._profiles[kind, self._stack[-1]].enable()

    def begin_tick(self, kind: str) -> None:
        """A control tick of ``kind`` starts: recorded into its profiles until the next."""
        if self._stack:
            self._ticks[kind] += 1
        self._switch(kind)

    def wrap_kind(self, function: Callable[..., Any], kind: str) -> Callable[..., Any]:
        """``function``, recorded into ``kind`` while it runs (each call counted as one of
        that kind), then back into the kind of the tick it was called from."""
        if kind not in self.kinds:
            raise ValueError(f"PartProfiler: unknown kind '{kind}' (valid: {self.kinds})")

        def recorded(*args: Any, **kwargs: Any) -> Any:
            if not self._stack:
                return function(*args, **kwargs)
            caller = self._kind
            self._ticks[kind] += 1
            self._switch(kind)
            try:
                return function(*args, **kwargs)
            finally:
                self._switch(caller)

        return recorded

    def wrap(self, function: Callable[..., Any], part: str) -> Callable[..., Any]:
        """``function``, recorded into ``part`` while it runs (the caller's part paused)."""
        if part not in self.parts:
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
        return {
            part: _ranked([self._profiles[k, part] for k in self.kinds], ticks, top)
            for part in self.parts
        }

    def hottest_by_kind(self, top: int = DEFAULT_TOP) -> dict[str, list[dict[str, Any]]]:
        """Each kind's ``top`` functions by own time in the controller's parts (all but the
        first), per tick of that kind (as :meth:`hottest`; ``share`` of the kind's time);
        kinds without a tick left out."""
        return {
            kind: _ranked([self._profiles[kind, p] for p in self.parts[1:]], count, top)
            for kind in self.kinds
            if (count := self._ticks[kind]) > 0
        }


def _ranked(profiles: Sequence[cProfile.Profile], ticks: int, top: int) -> list[dict[str, Any]]:
    """The ``top`` functions of ``profiles`` together by own time, per one of ``ticks``."""
    merged: pstats.Stats | None = None
    for profile in profiles:
        try:
            stats = pstats.Stats(profile)
        except TypeError:  # nothing recorded in this one
            continue
        merged = stats if merged is None else merged.add(stats)
    if merged is None:
        return []
    table = merged.stats  # type: ignore[attr-defined]
    rows = sorted(table.items(), key=lambda item: item[1][2], reverse=True)
    total = sum(row[2] for _, row in rows) or 1.0
    per_tick = 1e3 / max(ticks, 1)
    return [
        {
            "function": _name(key),
            "calls": int(row[1]),
            "own_ms_per_tick": row[2] * per_tick,
            "share": row[2] / total,
        }
        for key, row in rows[:top]
    ]


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


def profile_table(
    rows: Sequence[tuple[str, dict[str, list[dict[str, Any]]]]], by: str = "part"
) -> list[str]:
    """The profiles as Markdown lines: per pair and part (``by="part"``,
    :meth:`PartProfiler.hottest`) or kind of tick (``by="tick"``,
    :meth:`PartProfiler.hottest_by_kind`), its hottest functions."""
    per = "tick" if by == "part" else "such tick"
    lines = [
        "",
        f"| pair | {by} | function | calls | own time per {per} [ms] (profiled) | share of {by} |",
        "|---|---|---|---|---|---|",
    ]
    for pair, groups in rows:
        for group, functions in groups.items():
            for f in functions:
                lines.append(
                    f"| {pair} | {group} | `{f['function']}` | {f['calls']} | "
                    f"{f['own_ms_per_tick']:.3f} | {100 * f['share']:.0f} % |"
                )
    return lines
