"""The sweep's progress bar on standard error: rides done of total, falls so far per
controller, elapsed time and time left (tqdm's estimate from the rides done this run)."""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from typing import Any

from ridempc.sweep.stats import survived

__all__ = ["Progress"]


class Progress:
    """A tqdm bar over a sweep's rides.

    Args:
        total: Rides in the sweep.
        controllers: The controllers, in the order they are shown.
        done: Summaries already in the folder (a resumed sweep), counted at the start.
        enabled: False: no bar at all (the tests, ``--quiet`` uses).
    """

    def __init__(
        self,
        total: int,
        controllers: Sequence[str],
        done: Sequence[Mapping[str, Any]] = (),
        enabled: bool = True,
    ) -> None:
        self._falls = dict.fromkeys(controllers, 0)
        for summary in done:
            self._count(summary)
        self._bar = None
        if enabled:
            from tqdm import tqdm

            self._bar = tqdm(
                total=total,
                initial=len(done),
                unit="ride",
                file=sys.stderr,
                dynamic_ncols=True,
                smoothing=0.1,
            )
            self._bar.set_postfix_str(self._postfix(), refresh=False)

    def _count(self, summary: Mapping[str, Any]) -> None:
        controller = str(summary.get("controller"))
        if not survived(summary) and controller in self._falls:
            self._falls[controller] += 1

    def _postfix(self) -> str:
        return "falls " + ", ".join(f"{c} {n}" for c, n in self._falls.items())

    def update(self, summary: Mapping[str, Any]) -> None:
        """One ride ended (survived, fell or failed)."""
        self._count(summary)
        if self._bar is not None:
            self._bar.set_postfix_str(self._postfix(), refresh=False)
            self._bar.update(1)

    def close(self, finished: bool) -> None:
        """Close the bar; an unfinished one is erased (the command's line says why)."""
        if self._bar is not None:
            self._bar.leave = finished
            self._bar.close()
