"""The ``ridempc`` command: ``sim`` runs a ride, ``list`` names what exists.

Bad input exits with code 2 and one line on standard error naming the bad value and the
valid ones; a run that fails (diverged physics, a controller error) exits with code 1
after recording ``status: failed`` in its ``summary.json``. SIGINT (Ctrl-C) and SIGTERM
stop every command within a second, with code 130 or 143 and one line saying what was not
written (:mod:`ridempc.interrupts`). When the reader of standard output goes away
(``ridempc list | head -1``), the command ends quietly with code 141, as a Unix tool ended
by SIGPIPE does.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Sequence
from typing import NoReturn

from ridempc import options
from ridempc.autonomy import cli as navigate_cli
from ridempc.checks import writable_file
from ridempc.errors import ConfigError, RidempcError, UnknownNameError
from ridempc.interrupts import handled
from ridempc.options import EXIT_BAD_INPUT
from ridempc.paths import motion_library_dir
from ridempc.sweep import cli as sweep_cli
from ridempc.sweep import margin_cli
from ridempc.units import MAX_DURATION

__all__ = ["main"]

EXIT_FAILED = 1
EXIT_CLOSED_PIPE = 141  # 128 + SIGPIPE: what a shell reports for a writer whose reader left
DURATION_HELP = f"override duration [s], at most {MAX_DURATION:g}"
OUT_HELP = "output folder; the files an earlier sim or compare wrote there are replaced"


def _parser() -> argparse.ArgumentParser:
    parser = options.OneLineParser(
        prog="ridempc", description="Legged robots riding boards in MuJoCo."
    )
    commands = parser.add_subparsers(dest="command", required=True)

    sim = commands.add_parser("sim", help="run one ride and write its results to --out")
    sim.add_argument("--robot", default="cassie", help="robot name (default: cassie)")
    sim.add_argument("--board", default="none", help="board name, 'none' = flat ground")
    sim.add_argument("--controller", default="stand", help="controller name (default: stand)")
    sim.add_argument("--scenario", default="stand-still", help="scenario name or .toml file")
    sim.add_argument("--duration", type=options.duration, default=None, help=DURATION_HELP)
    sim.add_argument("--out", type=options.path, required=True, help=OUT_HELP)
    sim.add_argument(
        "--seed",
        type=options.bounded_int(0, options.MAX_SEED),
        default=0,
        help=f"random seed in [0, {options.MAX_SEED}] (default: 0)",
    )
    sim.add_argument("--video", action="store_true", help="render video.mp4 offscreen")
    sim.add_argument(
        "--snapshots",
        type=options.bounded_int(0, options.MAX_SNAPSHOTS),
        default=0,
        metavar="N",
        help=f"write snapshots.png, N frames evenly spaced over the ride, N <= "
        f"{options.MAX_SNAPSHOTS} (default: none)",
    )
    sim.add_argument("--no-plots", action="store_true", help="do not write plots.png")
    sim.add_argument("--viewer", action="store_true", help="open MuJoCo's interactive viewer")
    sim.add_argument(
        "--ground-truth",
        action="store_true",
        help="debugging only: put ground truth in the sensor packets (flagged in the summary)",
    )

    commands.add_parser("list", help="name the robots, boards, controllers and scenarios")

    compare = commands.add_parser(
        "compare", help="ride a scenario with the PD baseline and the MPC, same seeds, side by side"
    )
    compare.add_argument("--robot", required=True, help="robot name")
    compare.add_argument("--board", required=True, help="board name")
    compare.add_argument("--scenario", required=True, help="scenario name or .toml file")
    compare.add_argument(
        "--seeds",
        type=options.bounded_int(1, options.MAX_SEEDS),
        default=1,
        help=f"seeds 0..N-1, N in [1, {options.MAX_SEEDS}] (default: 1)",
    )
    compare.add_argument(
        "--controllers", default="pd,mpc", help="comma-separated controllers (default: pd,mpc)"
    )
    compare.add_argument("--duration", type=options.duration, default=None, help=DURATION_HELP)
    compare.add_argument(
        "--workers",
        type=options.bounded_int(1, options.MAX_JOBS),
        default=1,
        help=f"rides at once, 1 to {options.MAX_JOBS} (default: 1)",
    )
    compare.add_argument("--out", type=options.path, required=True, help=OUT_HELP)

    bench = commands.add_parser(
        "bench", help="MPC and WBC solve times on recorded problems, against other QP solvers"
    )
    bench.add_argument(
        "--pairs", default=None, help="comma-separated robot-board pairs (default: all)"
    )
    bench.add_argument(
        "--seconds",
        type=options.positive_seconds,
        default=None,
        help=f"simulated seconds recorded per pair, at most {options.MAX_BENCH_SECONDS:g} "
        "(default: 6)",
    )
    bench.add_argument(
        "--scenario",
        default=None,
        help="scenario recorded for every pair (default: each pair's manoeuvre, "
        "push-off-0.5 on the skateboard, velocity-steps for Cassie)",
    )
    bench.add_argument(
        "--wbc-solver",
        default=None,
        help="the whole-body QP's solver in the ride and its timing: daqp (default) or osqp",
    )
    bench.add_argument(
        "--profile",
        action="store_true",
        help="ride each pair again under cProfile: the hottest functions of each part of the "
        "tick and of each kind of tick (MPC tick, its build, take-up, standby, the others)",
    )
    bench.add_argument(
        "--json", type=options.path, default=None, help="also write the results here"
    )

    board = commands.add_parser("board", help="board tools")
    board_commands = board.add_subparsers(dest="board_command", required=True)
    identify = board_commands.add_parser(
        "identify", help="identify a board's reduced model from simulated experiments"
    )
    identify.add_argument("--board", required=True, help="board name")
    identify.add_argument(
        "--json", type=options.path, default=None, help="also write the result here"
    )

    library = commands.add_parser("library", help="motion libraries (trajectory optimisation)")
    library_commands = library.add_subparsers(dest="library_command", required=True)
    build = library_commands.add_parser("build", help="optimise and store a pair's trajectories")
    show = library_commands.add_parser("show", help="print a library's table, plot an entry")
    for sub in (build, show):
        sub.add_argument("--robot", required=True, help="robot name")
        sub.add_argument("--board", required=True, help="board name")
    build.add_argument("--targets", default=None, help="comma-separated targets, e.g. 0.3,0.5")
    build.add_argument(
        "--jobs",
        type=options.bounded_int(1, options.MAX_JOBS),
        default=1,
        help=f"worker processes, 1 to {options.MAX_JOBS} (default: 1)",
    )
    build.add_argument("--out", type=options.path, default=None, help="library folder")
    show.add_argument("--dir", type=options.path, default=None, help="library folder")
    show.add_argument(
        "--entry", type=options.entry_key, default=None, help="entry name or target, e.g. 0.5"
    )
    show.add_argument("--plot", type=options.path, default=None, help="write a PNG of the entry")
    sweep_cli.add_parser(commands)
    margin_cli.add_parser(commands)
    navigate_cli.add_parser(commands)
    return parser


def _identify(args: argparse.Namespace) -> int:
    import dataclasses

    from ridempc.boards import load_board
    from ridempc.io import atomic_write_json

    if args.json is not None:
        writable_file(args.json, "--json file")
    board = load_board(args.board)
    if board is None:
        raise ConfigError("board 'none' (flat ground) has no reduced model to identify")
    result = board.kind.identify(board)
    print(result.table())
    if args.json is not None:
        atomic_write_json(args.json, dataclasses.asdict(result))
    return 0


def _library(args: argparse.Namespace) -> int:
    from ridempc.library.cli import library_build, library_show

    if args.library_command == "build":
        return library_build(args.robot, args.board, args.targets, args.jobs, args.out)
    return library_show(args.robot, args.board, args.dir, args.entry, args.plot)


def _compare(args: argparse.Namespace) -> int:
    from ridempc.compare import compare

    controllers = [c.strip() for c in args.controllers.split(",") if c.strip()]
    rows = compare(
        args.robot,
        args.board,
        args.scenario,
        args.out,
        seeds=args.seeds,
        controllers=controllers,
        duration=args.duration,
        workers=args.workers,
    )
    print(f"results in {args.out}")
    failed = any(s["status"] == "failed" for r in rows for s in r.summaries)
    return EXIT_FAILED if failed else 0


def _bench(args: argparse.Namespace) -> int:
    from ridempc.bench import DEFAULT_SECONDS, bench

    if args.json is not None:  # checked in the first second of a ten-minute command
        writable_file(args.json, "--json file")
    if args.seconds is None:
        args.seconds = DEFAULT_SECONDS
    pairs = None if args.pairs is None else [p.strip() for p in args.pairs.split(",")]
    bench(
        pairs,
        seconds=args.seconds,
        json_path=args.json,
        scenario=args.scenario,
        wbc_solver=args.wbc_solver,
        profile=args.profile,
    )
    return 0


def _list() -> int:
    from ridempc.boards import board_names
    from ridempc.controllers import controller_names
    from ridempc.pair_description import pair_description_names
    from ridempc.robots import robot_names
    from ridempc.scenarios import scenario_applies, scenario_names
    from ridempc.sweep.distribution import distribution_boards, distribution_names

    print("robots:      " + ", ".join(robot_names()))
    print("boards:      " + ", ".join(board_names()))
    print("controllers: " + ", ".join(controller_names()))
    print("pairs:       " + ", ".join(pair_description_names()) + " (pairs/<robot>-<board>.toml)")
    print(
        "scenarios (robot 'none' with controller 'dead-weight' rides a board with a dead weight):"
    )
    riders = (*robot_names(), "none")
    for name in scenario_names():
        on = [b for b in board_names() if any(scenario_applies(name, r, b) for r in riders)]
        off = [b for b in board_names() if b not in on]
        robots = sorted({r for r in riders for b in on if scenario_applies(name, r, b)})
        line = f"  {name:<16} boards: {', '.join(on)}"
        if off:
            line += f" (does not apply to: {', '.join(off)})"
        print(line + f"; riders: {', '.join(robots)}")
    print("distributions (what a sweep draws; a .toml path too):")
    for name in distribution_names():
        print(f"  {name:<16} boards: {', '.join(distribution_boards(name))}")
    navigate_cli.list_courses()
    return 0


def _sim(args: argparse.Namespace) -> int:
    from ridempc.run import RideRequest, ride

    if args.viewer and args.video:
        raise ConfigError("--viewer and --video cannot be used together")
    if args.viewer and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        print(
            "ridempc: --viewer needs a display and none is available (DISPLAY is not set); "
            "running headless instead",
            file=sys.stderr,
        )
        args.viewer = False
    request = RideRequest(
        robot=args.robot,
        board=args.board,
        controller=args.controller,
        scenario=args.scenario,
        out=args.out,
        duration=args.duration,
        seed=args.seed,
        video=args.video,
        snapshots=args.snapshots,
        plots=not args.no_plots,
        viewer=args.viewer,
        ground_truth=args.ground_truth,
    )
    summary = ride(request)
    rtf = summary["real_time_factor"]
    line = (
        f"{summary['robot']}/{summary['board']}/{summary['controller']} "
        f"'{summary['scenario']}' seed {summary['seed']}: {summary['status']}"
    )
    if summary["fell"]:
        line += f" at {summary['fall_time_s']:.2f} s ({summary['fall_reason']})"
    if summary["error"]:
        line += f" ({summary['error']})"
    line += (
        f"; {summary['sim_time_s']:.2f} s simulated in {summary['wall_time_s']:.2f} s"
        f" ({rtf}x real time); results in {args.out}"
    )
    print(line)
    return EXIT_FAILED if summary["status"] == "failed" else 0


def _unwritten(args: argparse.Namespace) -> str:
    """What the command leaves incomplete when it is interrupted, for its one line."""
    if args.command == "sim":
        return f"no summary.json was written in {args.out}"
    if args.command == "compare":
        return f"no comparison.json was written in {args.out} (nor the ride under way's summary)"
    if args.command == "sweep":
        return sweep_cli.unwritten(args)
    if args.command == "bench":
        return "no results" + (f" were written to {args.json}" if args.json else " were printed")
    if args.command == "board":
        return "no result" + (f" was written to {args.json}" if args.json else " was printed")
    if args.command == "library" and args.library_command == "build":
        folder = args.out or motion_library_dir() / f"{args.robot}-{args.board}"
        return f"the entries under way were not stored in {folder} (the stored ones are complete)"
    if args.command == "margin":
        return margin_cli.unwritten(args)
    if args.command == "navigate":
        return navigate_cli.unwritten(args)
    if args.command == "library" and args.plot is not None:
        return f"no plot was written to {args.plot}"
    return "nothing was written"


def _dispatch(args: argparse.Namespace) -> int:
    if args.command == "list":
        return _list()
    if args.command == "board":
        return _identify(args)
    if args.command == "library":
        return _library(args)
    if args.command == "compare":
        return _compare(args)
    if args.command == "bench":
        return _bench(args)
    if args.command == "sweep":
        return sweep_cli.run(args)
    if args.command == "margin":
        return margin_cli.run(args)
    if args.command == "navigate":
        return navigate_cli.run(args)
    return _sim(args)


def _finish(args: argparse.Namespace) -> int:
    """The command's exit code: bad input, a failed run and a closed pipe as their codes."""
    try:
        code = _dispatch(args)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's shutdown
        return code
    except (UnknownNameError, ConfigError) as exc:
        print(f"ridempc: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except RidempcError as exc:
        print(f"ridempc: failed: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except BrokenPipeError:  # the reader of standard output went away (``| head -1``)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # what is still buffered goes nowhere, quietly
        os.close(devnull)
        return EXIT_CLOSED_PIPE


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; its exit code (module docstring).

    Args:
        argv: The arguments, or None for the program's own (``sys.argv``): the process
            then ends after the command, and ignores SIGINT and SIGTERM once it is done.
    """
    with handled("nothing was written", process_ends=argv is None) as handling:
        try:
            args = _parser().parse_args(argv)
            handling.unwritten = _unwritten(args)
            code = _finish(args)
        except BaseException as exc:
            if handling.received is None and not isinstance(exc, KeyboardInterrupt):
                raise
            code = handling.report()  # whatever the interrupt raised on its way out
        else:
            if handling.received is None:
                return code
            code = handling.report()
    if argv is None:
        _end_now(code)
    return code


def _end_now(code: int) -> NoReturn:
    """End an interrupted program without the interpreter's shutdown: a solver's thread may
    still be inside compiled code, and a library's C++ destructors then abort the process
    (``terminate called without an active exception``, exit -6 instead of 130). Every result
    is written atomically, so nothing is lost by skipping the shutdown."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()
    os._exit(code)


if __name__ == "__main__":
    sys.exit(main())
