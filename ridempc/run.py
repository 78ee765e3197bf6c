"""One ride, start to finish: resolve names, build the scene, simulate, write the results.

A request names its controller and scenario, or carries the objects themselves (the Python
API, :mod:`ridempc.api`); without an output folder the ride writes nothing and only returns
its summary. The output folder receives ``log.npz`` (time series), optionally ``video.mp4``,
``snapshots.png`` (a strip of still frames) and ``plots.png``, and last of all
``summary.json``. Everything is checked before anything is written (:func:`check_request`);
every file is written atomically, and every file an earlier run wrote there is removed
before the new run starts (:mod:`ridempc.results`), so a folder never mixes two runs and an
interrupted run never leaves a summary that looks complete.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ridempc.boards import NO_BOARD, load_board
from ridempc.boards.steering import check_steering
from ridempc.checks import writable_dir
from ridempc.controllers import NO_ROBOT, make_controller
from ridempc.controllers.base import Controller
from ridempc.controllers.path_following import follow_path
from ridempc.errors import ConfigError, WriteFailed
from ridempc.io import atomic_write_json, atomic_write_npz
from ridempc.results import check_clearable, clear_results
from ridempc.robots import load_robot
from ridempc.scenarios import Scenario, load_scenario_file, resolve_scenario
from ridempc.scenarios.hold import check_hold
from ridempc.scenarios.path_metrics import path_metrics
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.levelling import step_levelling
from ridempc.sim.metrics import run_metrics
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import RunResult, Simulation
from ridempc.sim.terrain import lay_out_under
from ridempc.units import MAX_DURATION, MIN_DURATION

if TYPE_CHECKING:
    from ridempc.robots.robot import Robot
    from ridempc.sim.scene import Scene

__all__ = ["CheckedRide", "RideRequest", "check_request", "controller_label", "ride"]

DEFAULT_SCENARIO = "stand-still"


@dataclass(frozen=True)
class RideRequest:
    """What ``ridempc sim`` (or :func:`ridempc.api.ride`) asks for.

    Attributes:
        robot: Robot name.
        board: Board name (``none`` for flat ground).
        controller: Controller name, or a controller object built for this robot and board.
        scenario: Scenario name, path of a scenario file, or a scenario object.
        out: Output folder, or None to write nothing (no video, snapshots or viewer then).
        duration: Override of the scenario's duration [s], or None.
        seed: Seed of all random draws.
        video: Render ``video.mp4``.
        snapshots: Number of still frames for ``snapshots.png`` (0: none).
        plots: Write ``plots.png``.
        viewer: Show the interactive viewer (needs a display).
        ground_truth: Give the controller ground truth (debugging only; flagged in the summary).
        physics_hz: Physics rate [Hz].
        option_style: How messages name an option: ``--{}`` on the command line, ``{}``
            (the keyword argument) in the Python API.
    """

    robot: str
    board: str
    controller: str | Controller
    scenario: str | Path | Scenario
    out: Path | None
    duration: float | None = None
    seed: int = 0
    video: bool = False
    snapshots: int = 0
    plots: bool = True
    viewer: bool = False
    ground_truth: bool = False
    option_style: str = "--{}"
    physics_hz: int = DEFAULT_PHYSICS_HZ


@dataclass(frozen=True)
class CheckedRide:
    """A request with every name, file and number resolved and checked, its scene built and
    its simulation set up; nothing written yet.

    Attributes:
        robot: The robot, or None for a dead weight.
        board_name: The board's name (``none`` for flat ground).
        scenario: The scenario, with the request's duration.
        controller: The controller, or None for a dead weight.
        scene: The built scene.
        simulation: The simulation, ready to run.
        rider_height: Height of the rider's base at the start [m] (frames the cameras).
        frame_callbacks: Called with (model, data) at the frame rate, when the request
            renders or views anything; :func:`ride` adds its recorders here.
        out: The output folder (writable, or creatable), or None: nothing is written.
    """

    robot: Robot | None
    board_name: str
    scenario: Scenario
    controller: Controller | None
    scene: Scene
    simulation: Simulation
    rider_height: float
    frame_callbacks: list[Callable[[Any, Any], None]]
    out: Path | None


def check_request(request: RideRequest) -> CheckedRide:
    """Check everything a ride needs, before anything is written or simulated.

    The output folder first (in the command's first second), then the numbers, the names,
    the files, and last what only the built scene can tell (a disturbance's body, the
    rates): every bad input is found before an earlier run's results are touched.

    Raises:
        UnknownNameError: A name that does not exist.
        ConfigError: An output folder that cannot be written, a malformed scenario or
            parameter file, a duration out of range, a scenario that does not apply to
            the robot-board pair or its scene, or a controller object that is not a
            :class:`~ridempc.controllers.base.Controller` built for this robot and board.
    """
    out = None
    if request.out is not None:
        out = writable_dir(Path(request.out), request.option_style.format("out") + " folder")
        check_clearable(out)
    elif request.video or request.snapshots > 0 or request.viewer:
        raise ConfigError("a video, snapshots or the viewer need an output folder (out)")
    if request.duration is not None and not MIN_DURATION <= request.duration <= MAX_DURATION:
        raise ConfigError(  # NaN fails the comparison too
            f"{request.option_style.format('duration')} {request.duration}: allowed: seconds in "
            f"[{MIN_DURATION:g}, {MAX_DURATION:g}]"
        )
    if request.video:
        from ridempc.sim.video import require_video_writer

        require_video_writer()
    robot = None if request.robot == NO_ROBOT else load_robot(request.robot)
    board = load_board(request.board)
    board_name = board.name if board is not None else NO_BOARD
    scenario = _scenario(request.scenario, board_name)
    controller = _controller(request.controller, robot, board_name)
    if not scenario.applies_to(request.robot, board_name):
        raise ConfigError(
            f"scenario '{scenario.name}' does not apply to {request.robot} on board '{board_name}'"
        )
    dead_weight = None
    if robot is None:
        if board is None:
            raise ConfigError(f"robot '{NO_ROBOT}' (a dead weight) needs a board to ride")
        dead_weight = load_robot(board.params.dead_weight_robot).mass
    platforms = len(board.params.platform_sites) if board is not None else 0
    offsets = len(scenario.platform_offsets)
    if offsets and (platforms < 2 or offsets != platforms):  # only independent ones move
        raise ConfigError(
            f"scenario '{scenario.name}': field 'platform_offsets' has {offsets} entries; "
            f"allowed: none, or one per independent platform (board '{board_name}' has "
            f"{platforms if platforms > 1 else 'none'})"
        )
    check_steering(scenario, board)
    check_hold(scenario, robot.name if robot is not None else None, board_name)
    if scenario.push_off is not None and scenario.push_off.hold and controller is not None:
        controller.hold_speed()
    if scenario.path is not None and controller is not None:  # the rider steers onto it
        controller = follow_path(controller, scenario.path, board)
    if request.duration is not None:
        scenario = scenario.with_duration(request.duration)

    try:
        terrain = lay_out_under(scenario.terrain, board, board_name)
    except ConfigError as exc:
        given = str(request.scenario)
        path = isinstance(request.scenario, Path) or given.endswith(".toml") or "/" in given
        raise ConfigError(f"{given if path else f'scenario {scenario.name!r}'}: {exc}") from exc
    scene = build_scene(
        robot,
        request.physics_hz,
        board=board,
        dead_weight=dead_weight,
        foot_offset=scenario.foot_offset,
        platform_offsets=scenario.platform_offsets,
        terrain=terrain,
    )
    height = float(scene.data.xpos[scene.base_body, 2])
    frame_callbacks: list[Callable[[Any, Any], None]] = []

    def on_frame(model: Any, data: Any) -> None:
        for callback in frame_callbacks:
            callback(model, data)

    framed = request.video or request.viewer or request.snapshots > 0
    simulation = Simulation(  # checks the scenario against the scene (its bodies)
        scene,
        controller,
        scenario,
        seed=request.seed,
        ground_truth=request.ground_truth,
        on_frame=on_frame if framed else None,
    )
    return CheckedRide(
        robot, board_name, scenario, controller, scene, simulation, height, frame_callbacks, out
    )


def _scenario(scenario: str | Path | Scenario, board: str) -> Scenario:
    """The request's scenario: an object as it is, a path read, a name looked up."""
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, Path):
        return load_scenario_file(scenario)
    if not isinstance(scenario, str):
        raise ConfigError(
            f"scenario {type(scenario).__name__}: allowed: a library name, a .toml path "
            "or a ridempc.scenarios.Scenario"
        )
    return resolve_scenario(scenario, board)


def _controller(controller: str | Controller, robot: Robot | None, board: str) -> Controller | None:
    """The request's controller: a name made for the pair, an object checked against it."""
    if isinstance(controller, str):
        return make_controller(controller, robot, board)
    if not isinstance(controller, Controller):
        raise ConfigError(
            f"controller {type(controller).__name__}: allowed: a controller name or an "
            "instance of ridempc.controllers.base.Controller"
        )
    label = controller_label(controller)
    if robot is None:
        raise ConfigError(f"controller '{label}': a dead weight (robot '{NO_ROBOT}') takes none")
    built_for = getattr(getattr(controller, "robot", None), "name", None)
    if built_for != robot.name or getattr(controller, "board", None) != board:
        raise ConfigError(
            f"controller '{label}' was built for robot '{built_for}' on board "
            f"'{getattr(controller, 'board', None)}'; allowed: one built for robot "
            f"'{robot.name}' on board '{board}'"
        )
    return controller


def controller_label(controller: str | Controller) -> str:
    """A controller as ``summary.json`` names it: its name, or an object's ``name``
    attribute, else its class name."""
    if isinstance(controller, str):
        return controller
    name = getattr(controller, "name", None)
    return name if isinstance(name, str) and name else type(controller).__name__


def ride(request: RideRequest) -> dict[str, Any]:
    """Run one ride and write its results; returns the summary.

    Every file an earlier ``sim`` or ``compare`` wrote in the output folder is removed once
    everything is checked (:func:`check_request`), before the ride starts
    (:func:`~ridempc.results.clear_results`); nothing else there is touched. Without an
    output folder (``request.out`` None) nothing is written at all.

    Raises:
        UnknownNameError: A name that does not exist (before anything is written).
        ConfigError: See :func:`check_request` (before anything is written).
    """
    checked = check_request(request)
    robot, board_name, scenario = checked.robot, checked.board_name, checked.scenario
    scene, simulation = checked.scene, checked.simulation
    height = checked.rider_height  # frame the rider by its height
    frame_callbacks = checked.frame_callbacks

    label = controller_label(request.controller)
    out = checked.out  # nothing is removed or written before this point
    if out is None:
        result = simulation.run()
        return _summary(request, checked, result, label, files=[])
    clear_results(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # the folder changed since it was checked
        raise WriteFailed(out, exc) from exc
    video = None
    viewer = None
    strip = None
    if request.video:
        from ridempc.sim.video import VideoRecorder

        video = VideoRecorder(
            scene.model,
            out / "video.mp4",
            track_body=scene.base_body,
            distance=max(1.2, 3.0 * height),
        )
        frame_callbacks.append(video)
    elif request.viewer:
        from ridempc.sim.viewer import LiveViewer

        viewer = LiveViewer(scene.model, scene.data)
        frame_callbacks.append(viewer)
    if request.snapshots > 0:
        from ridempc.sim.snapshots import SnapshotStrip

        strip = SnapshotStrip(
            scene.model,
            out / "snapshots.png",
            track_body=scene.base_body,
            duration=scenario.duration,
            count=request.snapshots,
            distance=max(1.2, 3.0 * height),
        )
        frame_callbacks.append(strip)

    finished = False
    try:
        result = simulation.run()
        finished = True
    finally:
        if video is not None:
            video.close(keep=finished)
        if viewer is not None:
            viewer.close()
        if strip is not None and finished:
            strip.close(scene.data)
        elif strip is not None:
            strip.discard()

    atomic_write_npz(out / "log.npz", result.log)
    files = ["log.npz"]
    if video is not None and video.frames:
        files.append("video.mp4")
    if strip is not None and strip.frames:
        files.append("snapshots.png")
    if request.plots and result.log:
        from ridempc.sim.plots import plot_run

        title = f"{request.robot} / {board_name} / {label} / {scenario.name} (seed {request.seed})"
        plot_run(result.log, robot, out / "plots.png", title)
        files.append("plots.png")

    summary = _summary(request, checked, result, label, files)
    atomic_write_json(out / "summary.json", summary)
    return summary


def _summary(
    request: RideRequest, checked: CheckedRide, result: RunResult, label: str, files: list[str]
) -> dict[str, Any]:
    """The ride's ``summary.json`` (README: what a run writes)."""
    scenario, controller, scene = checked.scenario, checked.controller, checked.scene
    robot = checked.robot
    return {
        "robot": request.robot,
        "board": checked.board_name,
        "controller": label,
        "scenario": scenario.name,
        "seed": request.seed,
        "status": result.status,
        "error": result.error,
        "fell": result.fell,
        "fall_time_s": result.fall_time,
        "fall_reason": result.fall_reason,
        "sim_time_s": result.sim_time,
        "duration_s": scenario.duration,
        "wall_time_s": round(result.wall_time, 4),
        "real_time_factor": round(result.sim_time / result.wall_time, 3)
        if result.wall_time
        else None,
        "physics_hz": request.physics_hz,
        "controller_hz": controller.rate_hz if controller is not None else None,
        "ground_truth_feedback": request.ground_truth
        or (controller is not None and controller.uses_ground_truth),
        "rider_mass_kg": round(scene.rider_mass, 4),
        **run_metrics(result, scenario, robot),
        **step_levelling(result.log, scenario),
        **path_metrics(result.log, scenario),
        **(controller.summary() if controller is not None else {}),
        "files": files,
    }
