"""The command line's checked options: argparse types that refuse NaN, infinity and values
out of range, and a parser whose every error is one line and exit code 2.

``float("nan")`` and ``float("inf")`` parse, so argparse's ``type=float`` would take them;
each type here names the option, the bad value and what is allowed.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import NoReturn

from ridempc.units import MAX_DURATION, MIN_DURATION

__all__ = [
    "MAX_BENCH_SECONDS",
    "MAX_JOBS",
    "MAX_SEED",
    "MAX_SEEDS",
    "MAX_SNAPSHOTS",
    "OneLineParser",
    "bounded_float",
    "bounded_int",
    "duration",
    "entry_key",
    "path",
    "positive_seconds",
]

EXIT_BAD_INPUT = 2

# NumPy's legacy and MuJoCo-side seeds are 32-bit; one range keeps every seed reproducible.
MAX_SEED: int = 2**32 - 1
# A thousand seeds of two controllers is days of wall time: more is a typo.
MAX_SEEDS: int = 1000
# A strip of more frames than this is too narrow to read.
MAX_SNAPSHOTS: int = 64
# The library builder runs one process per entry at most; the largest library has 15.
MAX_JOBS: int = 64
# The bench keeps every MPC and WBC problem of its ride in memory; a minute is ten times
# the default recording.
MAX_BENCH_SECONDS: float = 60.0


class OneLineParser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors are one line, ``ridempc: error: ...``, exit 2.

    Its sub-command parsers are of the same class (argparse makes them with the parent's
    class), so ``ridempc sim --seed x`` is one line too.
    """

    def error(self, message: str) -> NoReturn:
        print(f"ridempc: error: {message} (see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(EXIT_BAD_INPUT)


def _number(text: str, allowed: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number; {allowed}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"'{text}' is not a finite number; {allowed}")
    return value


def _seconds(lower: float, upper: float) -> Callable[[str], float]:
    allowed = f"allowed: seconds in [{lower:g}, {upper:g}]"

    def parse(text: str) -> float:
        value = _number(text, allowed)
        if not lower <= value <= upper:
            raise argparse.ArgumentTypeError(f"{text} is out of range; {allowed}")
        return value

    return parse


duration = _seconds(MIN_DURATION, MAX_DURATION)
"""``--duration``: a ride's length [s], in [:data:`~ridempc.units.MIN_DURATION`,
:data:`~ridempc.units.MAX_DURATION`]: the same bounds as a scenario file's ``duration``."""
positive_seconds = _seconds(MIN_DURATION, MAX_BENCH_SECONDS)
"""``--seconds`` of the bench [s], in [:data:`~ridempc.units.MIN_DURATION`,
:data:`MAX_BENCH_SECONDS`]."""


def bounded_int(lower: int, upper: int) -> Callable[[str], int]:
    """An argparse type: a whole number in ``[lower, upper]``."""
    allowed = f"allowed: a whole number in [{lower}, {upper}]"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a whole number; {allowed}") from None
        if not lower <= value <= upper:
            raise argparse.ArgumentTypeError(f"{text} is out of range; {allowed}")
        return value

    parse.__name__ = "whole number"
    return parse


def bounded_float(lower: float, upper: float, unit: str) -> Callable[[str], float]:
    """An argparse type: a finite number of ``unit`` in ``[lower, upper]``."""
    allowed = f"allowed: {unit} in [{lower:g}, {upper:g}]"

    def parse(text: str) -> float:
        value = _number(text, allowed)
        if not lower <= value <= upper:
            raise argparse.ArgumentTypeError(f"{text} is out of range; {allowed}")
        return value

    parse.__name__ = unit
    return parse


def entry_key(text: str) -> str:
    """``--entry``: an entry's name, or its target as a finite number."""
    try:
        value = float(text)
    except ValueError:
        return text
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(
            f"'{text}' is not a finite number; allowed: an entry name or its target"
        )
    return text


def path(text: str) -> Path:
    """A path argument: not empty (``Path("")`` would silently be the current folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; allowed: a file or folder name")
    if "\0" in text:
        raise argparse.ArgumentTypeError(f"{text!r} holds a NUL byte; allowed: a path")
    return Path(text)
