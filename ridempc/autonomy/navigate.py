"""One autonomous ride over a course: check, build, ride, judge, write.

Everything is checked before anything is written or simulated: the names, the output
folder, the course file, and whether the goal can be reached at all (the global planner on
the course's boxes, the map a person would give it; unreachable is bad input). The ride
itself starts with an empty map: the planner learns the boxes from its camera. The folder
receives ``log.npz``, ``plots.png``, ``map.png``, optionally ``video.mp4``, and last
``summary.json``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.autonomy.camera import DepthCameraSpec
from ridempc.autonomy.command_source import SourcedScenario
from ridempc.autonomy.course import Course, resolve_course
from ridempc.autonomy.depth_sensor import DepthSensor, add_depth_camera
from ridempc.autonomy.dijkstra import NoPath
from ridempc.autonomy.evaluation import rasterise, score_cells
from ridempc.autonomy.global_plan import plan_global
from ridempc.autonomy.judge import CourseJudge
from ridempc.autonomy.navigator import Navigator, NavigatorSettings
from ridempc.autonomy.obstacles import add_obstacles, obstacle_geoms, place_obstacles
from ridempc.autonomy.occupancy import GridFrame, OccupancyGrid
from ridempc.boards import NO_BOARD, load_board
from ridempc.checks import writable_dir
from ridempc.controllers import make_controller
from ridempc.errors import ConfigError, WriteFailed
from ridempc.io import atomic_write_json, atomic_write_npz
from ridempc.results import check_clearable, clear_results
from ridempc.robots import load_robot
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.metrics import run_metrics
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from ridempc.sim.terrain import lay_out_under

__all__ = ["NavigateRequest", "check_reachable", "course_map", "map_frame", "navigate"]

Array = NDArray[np.float64]

MAP_RESOLUTION: float = 0.05  # [m] the voxels' horizontal size
REST_SPEED: float = 0.05  # [m/s] the MPC's own threshold of rest
MAP_MARGIN: float = 3.0  # [m] around the course's start, goal and boxes: the camera's reach


@dataclass(frozen=True)
class NavigateRequest:
    """What ``ridempc navigate`` asks for.

    Attributes:
        robot: Robot name.
        board: Board name.
        controller: Controller name.
        course: Course name or ``.toml`` path.
        out: Output folder, or None to write nothing.
        seed: Seed of the sensors' noise.
        camera: ``raycast`` (deterministic, no GPU) or ``render`` (MuJoCo offscreen).
        video: Render ``video.mp4``.
        plots: Write ``plots.png`` and ``map.png``.
    """

    robot: str
    board: str
    controller: str
    course: str
    out: Path | None
    seed: int = 0
    camera: str = "raycast"
    video: bool = False
    plots: bool = True


def map_frame(course: Course, resolution: float = MAP_RESOLUTION) -> GridFrame:
    """The map's window: the course's start, goal and boxes with ``MAP_MARGIN`` around."""
    points = [np.asarray(course.start[:2]), np.asarray(course.goal)]
    points += [box.corners() for box in course.obstacles]
    xy = np.vstack(points)
    low = np.floor((xy.min(axis=0) - MAP_MARGIN) / resolution) * resolution
    high = xy.max(axis=0) + MAP_MARGIN
    shape = np.ceil((high - low) / resolution).astype(int)
    return GridFrame((float(low[0]), float(low[1])), resolution, (int(shape[0]), int(shape[1])))


def course_map(course: Course) -> tuple[GridFrame, NDArray[np.bool_], Array]:
    """The map a person would give the planner: the course's boxes rasterised on
    :func:`map_frame`, each cell with its box's height [m] (-inf: free)."""
    frame = map_frame(course)
    occupied = rasterise(frame, course.obstacles)
    height = np.full(frame.shape, -np.inf)
    for box in course.obstacles:
        height[rasterise(frame, [box])] = box.size[2]
    return frame, occupied, height


def check_reachable(course: Course, where: str, settings: NavigatorSettings) -> Array:
    """The global plan over the course's own boxes (its path, shape (n, 2) [m]), as the
    navigator plans it: a box low and narrow enough is a lane between the feet, so a course
    whose only way is a straddle is reachable.

    Raises:
        ConfigError: The goal cannot be reached from the start.
    """
    frame, occupied, height = course_map(course)
    observed = np.ones(frame.shape, dtype=bool)
    start, goal = np.asarray(course.start[:2]), np.asarray(course.goal)
    try:
        return plan_global(frame, occupied, height, observed, start, goal, settings).path
    except NoPath as exc:
        raise ConfigError(
            f"{where}: field 'goal' = {list(course.goal)} is unreachable for a rider of radius "
            f"{settings.inscribed} m, straddling boxes at most {settings.straddle.max_height} m "
            f"tall and {settings.straddle.max_width} m wide ({exc}); allowed: a goal the "
            "global planner reaches"
        ) from exc


def _rest_index(log: dict[str, Array], arrived_at: float | None) -> int | None:
    """The log row where the rider first came to rest (below ``REST_SPEED``) after the
    planner's arrival, or None: the goal is judged there, not after the riders' standstill
    creep (the MPC rider's 1-4 cm/s at a zero command)."""
    if arrived_at is None or not log:
        return None
    after = (log["time"] >= arrived_at) & (np.abs(log["forward_velocity"]) < REST_SPEED)
    found = np.nonzero(after)[0]
    return int(found[0]) if len(found) else None


def navigate(request: NavigateRequest) -> dict[str, Any]:
    """Check, ride and write one course; returns the summary.

    Raises:
        UnknownNameError: A name that does not exist (before anything is written).
        ConfigError: Bad input (before anything is written or simulated).
    """
    out = None
    if request.out is not None:
        out = writable_dir(Path(request.out), "--out folder")
        check_clearable(out)
    if request.video and out is None:
        raise ConfigError("a video needs an output folder (out)")
    if request.video:
        from ridempc.sim.video import require_video_writer

        require_video_writer()
    robot = load_robot(request.robot)
    board = load_board(request.board)
    board_name = board.name if board is not None else NO_BOARD
    course = resolve_course(request.course)
    where = f"course '{request.course}'"
    if not course.applies_to(request.robot, board_name):
        raise ConfigError(f"{where} does not apply to {request.robot} on board '{board_name}'")
    settings = NavigatorSettings()
    local = course.in_start_frame()
    check_reachable(local, where, settings)
    controller = make_controller(request.controller, robot, board_name)
    assert controller is not None
    camera = DepthCameraSpec()

    def edit(spec: Any) -> None:
        add_obstacles(spec, local.obstacles)
        add_depth_camera(spec, robot.params.base_body, camera)

    try:
        terrain = lay_out_under(local.terrain, board, board_name)
    except ConfigError as exc:
        raise ConfigError(f"{where}: {exc}") from exc
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ, board=board, edit_spec=edit, terrain=terrain)
    origin = scene.data.xpos[scene.base_body, :2].copy()  # the course's start, in the scene
    place_obstacles(scene.model, origin, terrain.level_at if terrain is not None else None)
    scene.reset()
    boxes = tuple(
        b.moved((b.center[0] + origin[0], b.center[1] + origin[1]), b.yaw) for b in local.obstacles
    )
    goal = np.asarray(local.goal) + origin
    shifted = local.model_copy(
        update={"obstacles": boxes, "goal": tuple(goal), "start": (*origin, 0.0)}
    )
    grid = OccupancyGrid(map_frame(shifted))
    sensor = DepthSensor(
        scene.model, camera, np.random.default_rng(request.seed + 1), request.camera
    )
    navigator = Navigator(goal, grid, sensor, controller, scene.physics_hz, settings)
    judge = CourseJudge(scene, obstacle_geoms(scene.model))

    def external(t: float, model: Any, data: Any) -> None:
        navigator(t, model, data)
        judge(t, model, data)

    scenario = SourcedScenario(
        name=course.name, description=course.description, duration=course.duration
    ).with_source(navigator.command_at)
    height = float(scene.data.xpos[scene.base_body, 2])
    video = None
    if request.video and out is not None:
        from ridempc.sim.video import VideoRecorder

        video = VideoRecorder(
            scene.model,
            out / "video.mp4",
            track_body=scene.base_body,
            distance=max(1.2, 3.0 * height),
        )
    simulation = Simulation(
        scene, controller, scenario, seed=request.seed, external=external, on_frame=video
    )
    if out is not None:  # everything is checked: an earlier run's files go now
        clear_results(out)
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise WriteFailed(out, exc) from exc
    finished = False
    try:
        result = simulation.run()
        finished = True
    finally:
        sensor.close()
        if video is not None:
            video.close(keep=finished)

    ridden = result.log["base_position"][:, :2] if result.log else np.zeros((0, 2))
    distance = np.linalg.norm(ridden - goal, axis=1) if len(ridden) else np.zeros(0)
    within = np.nonzero(distance <= course.goal_tolerance)[0]
    times = result.log.get("time", np.zeros(0))
    rest = _rest_index(result.log, navigator.arrived_at)
    reached = rest is not None and distance[rest] <= course.goal_tolerance and not result.fell
    scores = score_cells(grid.frame, grid.occupied(), grid.observed, boxes, ridden)
    summary: dict[str, Any] = {
        "robot": request.robot,
        "board": board_name,
        "controller": request.controller,
        "course": course.name,
        "seed": request.seed,
        "camera": request.camera,
        "status": result.status,
        "error": result.error,
        "fell": result.fell,
        "fall_time_s": result.fall_time,
        "fall_reason": result.fall_reason,
        "reached": reached,
        "time_to_goal_s": float(times[within[0]]) if len(within) else None,
        "rest_distance_to_goal_m": round(float(distance[rest]), 4) if rest is not None else None,
        "rest_time_s": float(times[rest]) if rest is not None else None,
        "final_distance_to_goal_m": round(float(distance[-1]), 4) if len(distance) else None,
        "min_clearance_m": round(judge.min_clearance, 4)
        if np.isfinite(judge.min_clearance)
        else None,
        "collisions": len(judge.collisions),
        "collision_events": judge.collisions,
        "boxes_straddled": sum(bool(box.contains(ridden).any()) for box in boxes),
        "perception_precision": round(scores.precision, 4),
        "perception_recall": round(scores.recall, 4),
        "perception_false_share": round(scores.false_share, 5),
        **navigator.summary(),
        "sim_time_s": result.sim_time,
        "duration_s": course.duration,
        "wall_time_s": round(result.wall_time, 4),
        **run_metrics(result, scenario, robot),
        **controller.summary(),
    }
    if out is None:
        return summary
    atomic_write_npz(out / "log.npz", {**result.log, **navigator.trace_arrays()})
    files = ["log.npz"]
    if video is not None and video.frames:
        files.append("video.mp4")
    if request.plots and result.log:
        from ridempc.autonomy.map_plot import plot_map
        from ridempc.sim.plots import plot_run

        title = (
            f"{request.robot} / {board_name} / {request.controller} / {course.name} "
            f"(seed {request.seed})"
        )
        plot_run(result.log, robot, out / "plots.png", title)
        estimated = result.log.get("estimate_base_position", np.zeros((0, 3)))[:, :2]
        estimated = estimated[np.isfinite(estimated).all(axis=1)]
        plot_map(out / "map.png", grid, boxes, navigator.paths, ridden, estimated, goal, title)
        files += ["plots.png", "map.png"]
    summary["files"] = files
    atomic_write_json(out / "summary.json", summary)
    return summary
