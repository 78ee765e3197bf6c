"""``ridempc navigate``: ride a course autonomously, or time the planners (``--bench``).

Bad input (an unknown name, a malformed course, a goal inside a box or unreachable, an
unwritable ``--out``) is one line and exit code 2 before anything is simulated or written;
a ride that fails is recorded in ``summary.json`` and exits with 1.
"""

from __future__ import annotations

import argparse
from typing import Any

from ridempc import options

__all__ = ["add_parser", "list_courses", "run", "unwritten"]

CAMERA_MODES = ("raycast", "render")


def _camera(value: str) -> str:
    if value not in CAMERA_MODES:
        raise argparse.ArgumentTypeError(
            f"'{value}' is not a camera mode; allowed: {', '.join(CAMERA_MODES)}"
        )
    return value


def add_parser(commands: Any) -> None:
    """Add ``navigate`` to the command line's sub-commands."""
    nav = commands.add_parser(
        "navigate",
        help="ride an obstacle course: depth camera, occupancy map, Dijkstra and a timed "
        "elastic band drive the riding controller",
    )
    nav.add_argument("--robot", default="cassie", help="robot name (default: cassie)")
    nav.add_argument("--board", default="hovershoes", help="board name (default: hovershoes)")
    nav.add_argument("--controller", default="mpc", help="controller name: mpc (default) or pd")
    nav.add_argument("--course", default=None, help="course name or .toml file (ridempc list)")
    nav.add_argument("--out", type=options.path, default=None, help="output folder")
    nav.add_argument(
        "--seed",
        type=options.bounded_int(0, options.MAX_SEED),
        default=0,
        help=f"random seed in [0, {options.MAX_SEED}] (default: 0)",
    )
    nav.add_argument(
        "--camera",
        type=_camera,
        default="raycast",
        help="depth images ray-cast (raycast, default: deterministic, no GPU) or rendered "
        "offscreen by MuJoCo (render: MUJOCO_GL=egl on a headless machine)",
    )
    nav.add_argument("--video", action="store_true", help="render video.mp4 offscreen")
    nav.add_argument("--no-plots", action="store_true", help="write neither plots.png nor map.png")
    nav.add_argument(
        "--bench",
        action="store_true",
        help="time the planners instead of riding: global plan and TEB update (median, p99)",
    )
    nav.add_argument(
        "--json", type=options.path, default=None, help="with --bench: also write the results here"
    )


def list_courses() -> None:
    """Name the library's courses (for ``ridempc list``)."""
    from ridempc.autonomy.course import course_names, resolve_course

    print("courses (ridempc navigate --course; a .toml path too):")
    for name in course_names():
        course = resolve_course(name)
        riders = ", ".join(course.robots) or "any"
        boards = ", ".join(course.boards) or "any"
        print(f"  {name:<16} boards: {boards}; riders: {riders}; {course.description}")


def unwritten(args: argparse.Namespace) -> str:
    """What an interrupted ``navigate`` leaves incomplete, for its one line."""
    if args.bench:
        return "no results" + (f" were written to {args.json}" if args.json else " were printed")
    return f"no summary.json was written in {args.out}"


def run(args: argparse.Namespace) -> int:
    """Run ``ridempc navigate``; its exit code (0, or 1 if the ride failed)."""
    from ridempc.errors import ConfigError

    if args.bench:
        from ridempc.autonomy.bench import bench_planners
        from ridempc.checks import writable_file

        if args.json is not None:
            writable_file(args.json, "--json file")
        bench_planners(args.course, json_path=args.json)
        return 0
    if args.json is not None:
        raise ConfigError("navigate: --json writes the --bench results; allowed: with --bench")
    if args.course is None:
        raise ConfigError("navigate: --course is required (a course name or .toml file)")
    if args.out is None:
        raise ConfigError("navigate: --out is required (the output folder)")
    from ridempc.autonomy.navigate import NavigateRequest, navigate

    summary = navigate(
        NavigateRequest(
            robot=args.robot,
            board=args.board,
            controller=args.controller,
            course=args.course,
            out=args.out,
            seed=args.seed,
            camera=args.camera,
            video=args.video,
            plots=not args.no_plots,
        )
    )
    line = (
        f"{summary['robot']}/{summary['board']}/{summary['controller']} course "
        f"'{summary['course']}' seed {summary['seed']}: {summary['status']}, "
        f"{'reached' if summary['reached'] else 'not reached'}"
    )
    if summary["time_to_goal_s"] is not None:
        line += f" in {summary['time_to_goal_s']:.1f} s"
    line += f", min clearance {summary['min_clearance_m']} m, {summary['collisions']} collisions"
    if summary["fell"]:
        line += f"; fell at {summary['fall_time_s']:.2f} s ({summary['fall_reason']})"
    if summary["stop_reason"]:
        line += f"; stopped: {summary['stop_reason']}"
    print(line + f"; results in {args.out}")
    return 1 if summary["status"] == "failed" else 0
