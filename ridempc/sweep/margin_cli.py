"""``ridempc margin``: its options, checked, and the command.

Bad input (an unknown name, a number out of range, an unwritable ``--out``) is one line and
exit code 2 before any ride; a ride that fails is reported in the table and ``margin.json``
and the command exits with 1; an interrupt leaves no ``margin.json``.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from ridempc import options

__all__ = [
    "DEFAULT_CHECKS",
    "DEFAULT_DIRECTIONS",
    "DEFAULT_FIRST_PUSH",
    "DEFAULT_MAX_PUSH",
    "DEFAULT_TOLERANCE",
    "MAX_DIRECTIONS",
    "add_parser",
    "run",
    "unwritten",
]

DEFAULT_DIRECTIONS: int = 8  # the issue's: forward, back, both sides and the diagonals
# 5° apart: finer than a margin changes between neighbours, and each direction costs ~12 rides.
MAX_DIRECTIONS: int = 72
# [N/kg] a tenth of the library's 1 N/kg push: finer than the outcome near the boundary is
# reproducible (a rounding-level change flips a ride there: docs/tuning.md), and each
# halving of it costs one more ride per direction.
DEFAULT_TOLERANCE: float = 0.1
_TOLERANCE_RANGE: tuple[float, float] = (0.01, 10.0)  # [N/kg] 0.01: the magnitudes' rounding
DEFAULT_FIRST_PUSH: float = 1.0  # [N/kg] the library's push, which every rider survives
# [N/kg] a 0.2 s push of 32 N/kg changes the base's speed by 6.4 m/s: no rider on a board
# survives it, so the bracket (1, 2, 4, ..., 32) always closes.
DEFAULT_MAX_PUSH: float = 32.0
_MAX_PUSH_RANGE: tuple[float, float] = (0.1, 100.0)  # [N/kg] the scenarios' bound: ten g
DEFAULT_CHECKS: int = 2  # rides below each boundary looking for a non-monotone outcome
_MAX_CHECKS: int = 10
_PUSH_TIME_RANGE: tuple[float, float] = (0.0, 60.0)  # [s] the push within the first minute
_AFTER_RANGE: tuple[float, float] = (0.5, 60.0)  # [s] a fall shows within half a second at least


def add_parser(commands: Any) -> None:
    """Add ``margin`` to the command line's sub-commands."""
    from ridempc.sweep.pushes import DURATION_AFTER_S, PUSH_DURATION_S, PUSH_TIME_S

    margin = commands.add_parser(
        "margin",
        help=f"the largest push on the base ({PUSH_DURATION_S:g} s, N/kg) a rider survives, "
        "per direction, by bisection",
    )
    margin.add_argument("--robot", required=True, help="robot name")
    margin.add_argument("--board", required=True, help="board name")
    margin.add_argument("--controller", required=True, help="controller name")
    margin.add_argument(
        "--scenario",
        default="stand-still",
        help="scenario pushed, name or .toml file (default: stand-still); its duration is replaced",
    )
    margin.add_argument(
        "--directions",
        type=options.bounded_int(1, MAX_DIRECTIONS),
        default=DEFAULT_DIRECTIONS,
        help=f"push directions, evenly spaced from forward, counter-clockwise, 1 to "
        f"{MAX_DIRECTIONS} (default: {DEFAULT_DIRECTIONS})",
    )
    margin.add_argument(
        "--seed",
        type=options.bounded_int(0, options.MAX_SEED),
        default=0,
        help=f"seed of every ride, in [0, {options.MAX_SEED}] (default: 0)",
    )
    margin.add_argument(
        "--workers",
        type=options.bounded_int(1, options.MAX_JOBS),
        default=None,
        help=f"worker processes, 1 to {options.MAX_JOBS} (default: the machine's cores)",
    )
    margin.add_argument(
        "--tolerance",
        type=options.bounded_float(*_TOLERANCE_RANGE, "N/kg"),
        default=DEFAULT_TOLERANCE,
        help=f"bisection stops at this bracket [N/kg] (default: {DEFAULT_TOLERANCE:g})",
    )
    margin.add_argument(
        "--max-push",
        type=options.bounded_float(*_MAX_PUSH_RANGE, "N/kg"),
        default=DEFAULT_MAX_PUSH,
        help=f"largest push ridden [N/kg] (default: {DEFAULT_MAX_PUSH:g})",
    )
    margin.add_argument(
        "--checks",
        type=options.bounded_int(0, _MAX_CHECKS),
        default=DEFAULT_CHECKS,
        help=f"rides below each boundary that look for a fall there, 0 to {_MAX_CHECKS} "
        f"(default: {DEFAULT_CHECKS})",
    )
    margin.add_argument(
        "--push-time",
        type=options.bounded_float(*_PUSH_TIME_RANGE, "seconds"),
        default=PUSH_TIME_S,
        help=f"when the push starts [s] (default: {PUSH_TIME_S:g}, after the start-up)",
    )
    margin.add_argument(
        "--duration-after",
        type=options.bounded_float(*_AFTER_RANGE, "seconds"),
        default=DURATION_AFTER_S,
        help=f"ridden after the push starts, to tell a fall [s] (default: {DURATION_AFTER_S:g})",
    )
    margin.add_argument(
        "--out",
        type=options.path,
        required=True,
        help="output folder; the files an earlier margin, sim or compare wrote there are replaced",
    )


def unwritten(args: argparse.Namespace) -> str:
    """What an interrupted ``margin`` leaves incomplete, for its one line."""
    return f"no margin.json was written in {args.out}"


def run(args: argparse.Namespace) -> int:
    """Run ``ridempc margin``; its exit code (0, or 1 if a ride failed)."""
    from ridempc.boards import NO_BOARD, load_board
    from ridempc.errors import WriteFailed
    from ridempc.scenarios import resolve_scenario
    from ridempc.sweep.bisection import Search
    from ridempc.sweep.margin import MarginSpec, check_spec, run_margin
    from ridempc.sweep.margin_files import (
        check_margin_out,
        clear_margin,
        margin_table,
        write_margin,
    )

    out = check_margin_out(args.out)
    board = load_board(args.board)
    spec = MarginSpec(
        robot=args.robot,
        board=args.board,
        controller=args.controller,
        scenario=resolve_scenario(args.scenario, board.name if board is not None else NO_BOARD),
        seed=args.seed,
        directions=args.directions,
        push_time=args.push_time,
        duration_after=args.duration_after,
        search=Search(
            tolerance=args.tolerance,
            start=min(DEFAULT_FIRST_PUSH, args.max_push),
            cap=args.max_push,
            checks=args.checks,
        ),
    )
    check_spec(spec)
    clear_margin(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # the folder changed since it was checked
        raise WriteFailed(out, exc) from exc
    result = run_margin(spec, args.workers or os.cpu_count() or 1)
    write_margin(out, result)
    print(margin_table(result))
    print(f"results in {out}")
    if result.failed:
        print(
            f"ridempc: failed: {result.failed} ride(s) failed; their errors are in "
            f"{out / 'margin.json'}",
            file=sys.stderr,
        )
        return 1
    return 0
