"""The navigator: camera frames and the estimated pose in, speed and yaw-rate commands out.

Called at every physics step (the simulation's ``external`` hook), it captures a depth
frame at the camera's rate, and at ``planner_hz`` (the paper's 10 Hz) fuses the frames
delivered since (:class:`~ridempc.autonomy.perception.Perception`), replans the global path
at ``global_hz`` (Dijkstra over the inflated costmap) and solves the timed elastic band to
a local goal ``LOOK_AHEAD`` along it. The band's first segment is the command the riding
controller reads (:meth:`Navigator.command_at`, also its command preview), reached at the
riders' acceleration limits. It sees the camera's depth images and the controller's state
estimate, never the scene.

A low obstacle narrow enough to pass between the feet (:mod:`ridempc.autonomy.straddle`)
is not ridden round: the path runs along its axis and the feet are spread around it (the
wave pattern's lateral offset in the command).

On an incline measured on the map's ground ahead (:mod:`ridempc.autonomy.incline`) the speed
command holds ``cruise`` and the yaw-rate command is bounded by ``incline_yaw_rate``: gravity
there moves the riders' speed off their command faster than the command slews, a command cut
far below the speed makes the MPC rider brake by its ``stop`` manoeuvre, and its turns there
overshoot their command (both spun it, on the incline and in a turn).

A band that fails ``failures_to_stop`` times in a row, or a goal that becomes unreachable,
stops the rider (it slows at ``stop_decel`` and holds); the summary records when and why.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import binary_dilation

from ridempc.autonomy.camera import CameraIntrinsics
from ridempc.autonomy.costmap import Costmap
from ridempc.autonomy.depth_sensor import DepthSensor, mount_pose
from ridempc.autonomy.dijkstra import NoPath
from ridempc.autonomy.global_plan import plan_global
from ridempc.autonomy.incline import incline_ahead
from ridempc.autonomy.occupancy import GridFrame, OccupancyGrid
from ridempc.autonomy.perception import Perception
from ridempc.autonomy.straddle import (
    Straddle,
    StraddleSettings,
    lane_walls,
)
from ridempc.autonomy.straddle_decision import StraddleTracker
from ridempc.autonomy.teb import LOOK_AHEAD, TebPlanner, TebSettings
from ridempc.controllers.base import Controller
from ridempc.scenarios.scenario import Command

__all__ = ["Navigator", "NavigatorSettings", "nearby_cells", "nearby_obstacles"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class NavigatorSettings:
    """Rates, limits and the costmap's shape.

    Attributes:
        planner_hz: Local planner rate [Hz] (the paper's 10).
        global_hz: Global replanning rate [Hz].
        start_delay: Standing time before the rider sets off [s] (the riders settle).
        accel: Speed command's rate limit [m/s^2].
        yaw_accel: Yaw-rate command's rate limit [rad/s^2].
        turn_at_rest: Largest yaw rate commanded at a standstill [rad/s]; the riders turn
            by leaning and steer the shoes apart, so a yaw rate needs speed.
        turn_radius: Beyond ``turn_at_rest``, the yaw rate is at most speed over this [m].
        stop_decel: Deceleration of a stop [m/s^2].
        inscribed: Rider's inscribed radius in the costmap [m] (Cassie's stance on the shoes).
        decay: Costmap decay rate [1/m].
        unknown_cost: Cost added to the cells never seen: a path through known free space
            is preferred to a shorter one through the unknown, unless much shorter.
        global_coarsening: The global planner's cells are this many map cells wide (10 cm:
            the band refines the path; a quarter of the cells, a quarter of the time).
        arrive: Distance to the goal at which the speed command steps to zero [m]: the
            MPC rider's motion library stops from 0.5 m/s in 0.45 m (``stop-0.50``).
        cruise: Speed the rider rides at [m/s] (the MPC's library rides at 0.5 m/s; it
            holds any lower command that is not rest at that).
        min_speed: Slowest speed commanded while riding [m/s]: the MPC rider starts its
            stop manoeuvre when more than 0.25 m/s faster than its command.
        hold_gain: At the goal, speed per metre of the goal ahead (behind: negative) [1/s]:
            the riders creep a few centimetres a second when told to stand still.
        hold_speed: Largest speed of that hold [m/s], below the MPC's 0.05 m/s of rest.
        failures_to_stop: Band failures in a row that stop the rider.
        obstacle_radius: Map cells within this distance are the band's obstacles [m].
        incline_hold: On an incline at least this steep [rad] the speed command holds
            ``cruise`` (no slowing for turns): gravity's pull along the shoes, g sin 3 deg =
            0.51 m/s^2, is twice ``accel``, so the speed leaves its command faster than the
            command slews (the MPC rider climbed the slope course at 0.62-0.74 m/s against
            0.5), and a turn's cut to ``min_speed`` then fell 0.44 m/s below the speed: the
            MPC rider's ``stop`` manoeuvre, which spun and fell there.
        incline_reach: The incline is measured this far ahead [m]: the command holds before
            the shoes reach it (the command horizon and the slew from ``min_speed``,
            0.5 s + 0.8 s at 0.5 m/s, are 0.65 m).
        incline_behind: ... and from this far behind the base [m] (the shoes' contact
            patches behind the pelvis, with the fit's half window).
        incline_yaw_rate: Largest yaw rate commanded on such an incline [rad/s]: there the
            MPC rider turned at 2-3 times its command (0.71-1.07 rad/s at 0.35) and spun;
            at this, thrice is 0.45 rad/s, within the 0.5 rad/s it tracks on the level.
        command_horizon: The command is the band's mean speed and yaw rate over its first
            this many seconds [s] (the riders lag their command by about that much).
        teb: The band's settings.
        straddle: What is passed between the feet, and how.
    """

    planner_hz: float = 10.0
    global_hz: float = 1.0
    start_delay: float = 2.0
    accel: float = 0.25
    yaw_accel: float = 0.3
    turn_at_rest: float = 0.1
    turn_radius: float = 1.0
    stop_decel: float = 0.25
    inscribed: float = 0.35
    decay: float = 3.0
    global_coarsening: int = 2
    unknown_cost: float = 0.3
    arrive: float = 0.45
    cruise: float = 0.5
    min_speed: float = 0.3
    hold_gain: float = 0.5
    hold_speed: float = 0.04
    failures_to_stop: int = 3
    obstacle_radius: float = 2.5
    incline_hold: float = math.radians(3.0)
    incline_reach: float = 1.0
    incline_behind: float = 0.3
    incline_yaw_rate: float = 0.15
    command_horizon: float = 0.5
    teb: TebSettings = field(default_factory=TebSettings)
    straddle: StraddleSettings = field(default_factory=StraddleSettings)


class Navigator:
    """Plans and commands one ride.

    Args:
        goal: Goal (x, y) in the scene [m].
        grid: The global occupancy grid (empty: the course is unknown).
        sensor: The depth camera.
        controller: The riding controller (its ``estimate()`` is the pose).
        physics_hz: Physics rate [Hz].
        settings: Rates and limits.
    """

    def __init__(
        self,
        goal: Array,
        grid: OccupancyGrid,
        sensor: DepthSensor,
        controller: Controller,
        physics_hz: int,
        settings: NavigatorSettings | None = None,
    ) -> None:
        self.settings = s = settings or NavigatorSettings()
        self.goal = np.asarray(goal, dtype=float)
        self.grid = grid
        self.sensor = sensor
        self.controller = controller
        self.physics_hz = physics_hz
        intrinsics = CameraIntrinsics.of(sensor.spec)
        self.perception = Perception(grid, sensor.rays, intrinsics.fovx)
        self.teb = TebPlanner(s.teb)
        self._mount, self._mount_rotation = mount_pose(sensor.spec)
        self._camera_every = max(1, round(physics_hz / sensor.spec.rate_hz))
        self._plan_every = max(1, round(physics_hz / s.planner_hz))
        self._global_every = max(1, round(physics_hz / s.global_hz))
        self._poses: dict[float, tuple[Array, Array]] = {}  # capture time -> estimated pose
        self.path: Array = np.zeros((0, 2))
        self.paths: list[Array] = []
        self.costmap: Costmap | None = None
        self._command = (0.0, 0.0, 0.0)  # (time, speed, yaw rate) of the last command
        self._target = (0.0, 0.0)
        self._spread = (0.0, 0.0, 0.0)  # (time, offset, target offset) of the feet [s, m, m]
        self.straddles: tuple[Straddle, ...] = ()
        self.straddle_tracker = StraddleTracker(s.straddle)
        # cells that are not the band's obstacles: far specks, and the straddles' cells with
        # those joining them (a box grows as it is seen, between replans)
        self._passed = np.zeros(grid.frame.shape, dtype=bool)
        self.straddle_times: list[float] = []  # update times at which the feet were spread
        self._decel = s.accel
        self._failures_in_row = 0
        self.arrived_at: float | None = None
        self.stopped_at: float | None = None
        self.stop_reason: str | None = None
        self.band_failures = 0
        self.teb_times: list[float] = []
        self.incline_times: list[float] = []  # update times at which an incline held the speed
        self.steepest = 0.0  # steepest incline measured ahead [rad]
        self.global_times: list[float] = []
        self.perception_times: list[float] = []
        self.bands: list[Array] = []
        self.trace: list[tuple[float, float, float, float, float, float]] = []

    # -- what the riding controller reads ---------------------------------------------------
    def command_at(self, t: float) -> Command:
        """The command at time ``t`` [s]: the last one ramped towards the planner's target
        at the rate limits (for a later ``t``, the preview of that ramp)."""
        t0, v0, w0 = self._command
        dt = max(0.0, t - t0)
        v1, w1 = self._target
        limit = self._decel if v1 < v0 else self.settings.accel
        v = v0 + float(np.clip(v1 - v0, -limit * dt, limit * dt))
        w = w0 + float(
            np.clip(w1 - w0, -self.settings.yaw_accel * dt, self.settings.yaw_accel * dt)
        )
        t1, offset, wanted = self._spread
        rate = self.settings.straddle.spread_rate * max(0.0, t - t1)
        offset += float(np.clip(wanted - offset, -rate, rate))
        return Command.model_construct(velocity=v, yaw_rate=w, lateral_offset=offset)

    def _respread(self, t: float, offset: float) -> None:
        if offset != self._spread[2]:
            self._spread = (t, self.command_at(t).lateral_offset, offset)

    def _retarget(self, t: float, speed: float, yaw_rate: float) -> None:
        now = self.command_at(t)
        self._command = (t, now.velocity, now.yaw_rate)
        self._target = (speed, yaw_rate)

    # -- the simulation's hook --------------------------------------------------------------
    def __call__(self, t: float, model: object, data: object) -> None:
        tick = round(t * self.physics_hz)
        if tick % self._camera_every == 0:
            self.sensor.capture(t, data)
            pose = self._pose()
            if pose is not None:
                self._poses[t] = pose
        if tick % self._plan_every == 0:
            self._plan(tick, t)

    def _pose(self) -> tuple[Array, Array] | None:
        """The estimated base position [m] and base-to-world rotation, or None."""
        estimate = self.controller.estimate()
        if estimate is None:
            return None
        w, x, y, z = estimate.base_quaternion
        rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        return np.asarray(estimate.base_position, dtype=float), rotation

    def _perceive(self, t: float) -> None:
        frame = self.sensor.delivered(t)
        if frame is None or frame.time not in self._poses:
            return
        base, rotation = self._poses.pop(frame.time)
        for stale in [k for k in self._poses if k < frame.time]:
            del self._poses[stale]
        camera_rotation = rotation @ self._mount_rotation
        camera_position = base + rotation @ self._mount
        yaw = math.atan2(rotation[1, 0], rotation[0, 0])
        perceived = self.perception.update(frame.depth, camera_rotation, camera_position, base, yaw)
        self.perception_times.append(perceived.elapsed)

    def _plan(self, tick: int, t: float) -> None:
        self._perceive(t)
        pose = self._pose()
        if pose is None or self.stopped_at is not None:
            return
        base, rotation = pose
        yaw = math.atan2(rotation[1, 0], rotation[0, 0])
        self._respread(t, self._straddle_spread(base[:2]))
        if self._spread[2] > 0.0:
            self.straddle_times.append(t)
        to_goal = float(np.hypot(*(self.goal - base[:2])))
        if self.arrived_at is None and to_goal <= self.settings.arrive:
            self._command = (t, 0.0, 0.0)  # a step: the riders brake as they were built to
            self.arrived_at = t
            self._decel = self.settings.stop_decel
        if self.arrived_at is not None:  # hold at the goal: a rider left alone creeps
            ahead = float((self.goal - base[:2]) @ rotation[:2, 0])
            hold = self.settings.hold_speed
            self._retarget(t, float(np.clip(self.settings.hold_gain * ahead, -hold, hold)), 0.0)
            return
        if t < self.settings.start_delay:
            return
        if tick % self._global_every == 0 or len(self.path) == 0:
            if not self._replan(base[:2], t):
                return
        local_goal = self._local_goal(base[:2])
        obstacles = self._nearby_obstacles(base[:2])
        now = self.command_at(t)
        band = self.teb.solve(
            np.array([base[0], base[1], yaw]), local_goal, obstacles, now.velocity, now.yaw_rate
        )
        self.teb_times.append(band.solve_time)
        if not band.success:
            self.band_failures += 1
            self._failures_in_row += 1
            if self._failures_in_row >= self.settings.failures_to_stop:
                self._stop(t, f"the local planner failed {self._failures_in_row} times in a row")
            return
        self._failures_in_row = 0
        self.bands.append(band.poses)
        v, w = band.command(self.settings.command_horizon)
        self.trace.append((t, v, w, *local_goal))
        incline = incline_ahead(
            self.grid.frame,
            self.grid.ground,
            base[:2],
            yaw,
            self.settings.incline_reach,
            self.settings.incline_behind,
            self.grid.occupied(),
        )
        self.steepest = max(self.steepest, incline)
        s = self.settings
        on_incline = incline >= s.incline_hold
        if on_incline:
            self.incline_times.append(t)
        v = max(s.cruise if on_incline else s.min_speed, min(v, s.cruise))
        turn = s.incline_yaw_rate if on_incline else s.turn_at_rest + v / s.turn_radius
        w = float(np.clip(w, -turn, turn))
        self._decel = self.settings.accel
        self._retarget(t, v, w)

    def _straddle_spread(self, position: Array) -> float:
        """The feet's lateral offset wanted at ``position`` [m]: spread within the lead of
        a straddle and near its axis (wider than its lane: once lined up, spread)."""
        st = self.settings.straddle
        for straddle in self.straddles:
            if straddle.in_lane(position, st.lane + straddle.half_width, st.lead):
                return st.spread
        return 0.0

    def _replan(self, start: Array, t: float) -> bool:
        began = time.perf_counter()
        grid = self.grid
        try:
            planned = plan_global(
                grid.frame,
                grid.occupied(),
                grid.height,
                grid.observed,
                start,
                self.goal,
                self.settings,
                self.straddle_tracker,
            )
        except NoPath as exc:
            self.global_times.append(time.perf_counter() - began)
            self._stop(t, f"global planner: {exc}")
            return False
        self.global_times.append(time.perf_counter() - began)
        self.costmap, self.straddles = planned.costmap, planned.straddles
        join = round(self.settings.straddle.join / grid.frame.resolution)
        straddled = np.zeros(grid.frame.shape, dtype=bool)
        for straddle in planned.straddles:
            straddled |= straddle.cells
        reach = np.ones((2 * join + 1, 2 * join + 1), dtype=bool)
        self._passed = planned.ignored | binary_dilation(straddled, structure=reach)
        self.path = planned.path
        self.paths.append(self.path)
        return True

    def _local_goal(self, position: Array) -> Array:
        """The pose ``LOOK_AHEAD`` along the global path from its point nearest the rider
        (the straddle's shorter look-ahead while the feet are spread: a lateral error is
        closed over about that distance)."""
        ahead = self.settings.straddle.look_ahead if self._spread[2] > 0.0 else LOOK_AHEAD
        path = self.path
        nearest = int(np.argmin(np.linalg.norm(path - position, axis=1)))
        rest = np.vstack([position, path[nearest:], self.goal])
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(rest, axis=0), axis=1))])
        if arc[-1] <= ahead:
            d = rest[-1] - rest[max(0, len(rest) - 6)]
            return np.array([*self.goal, math.atan2(d[1], d[0])])
        k = int(np.searchsorted(arc, ahead))
        point = rest[k]
        d = rest[min(len(rest) - 1, k + 3)] - rest[max(0, k - 3)]
        return np.array([point[0], point[1], math.atan2(d[1], d[0])])

    def _nearby_obstacles(self, position: Array) -> Array:
        obstacles = self.grid.occupied() & ~self._passed
        return nearby_obstacles(self.grid.frame, obstacles, self.straddles, position, self.settings)

    def trace_arrays(self) -> dict[str, Array]:
        """Every band's time [s], command (speed [m/s], yaw rate [rad/s]) and local goal
        (x, y [m], heading [rad]), for ``log.npz``."""
        trace = np.array(self.trace).reshape(-1, 6)
        return {
            "planner_time": trace[:, 0],
            "planner_command": trace[:, 1:3],
            "planner_local_goal": trace[:, 3:],
        }

    def _stop(self, t: float, reason: str) -> None:
        self.stopped_at = t
        self.stop_reason = reason
        self._decel = self.settings.stop_decel
        self._retarget(t, 0.0, 0.0)

    def summary(self) -> dict[str, object]:
        """The planner's figures for ``summary.json``."""
        return {
            "arrived_at_s": self.arrived_at,
            "stopped_at_s": self.stopped_at,
            "stop_reason": self.stop_reason,
            "band_failures": self.band_failures,
            "teb_ms": _stats(self.teb_times),
            "global_plan_ms": _stats(self.global_times),
            "perception_ms": _stats(self.perception_times),
            "teb_updates": len(self.teb_times),
            "global_plans": len(self.global_times),
            "frames_fused": len(self.perception_times),
            "straddles": [
                {
                    "center_m": [round(float(v), 3) for v in st.center],
                    "axis": [round(float(v), 3) for v in st.axis],
                    "width_m": round(2.0 * st.half_width, 3),
                    "length_m": round(2.0 * st.half_length, 3),
                    "height_m": round(st.height, 3),
                }
                for st in self.straddles
            ],
            "feet_spread_s": round(len(self.straddle_times) / self.settings.planner_hz, 2),
            "incline_hold_s": round(len(self.incline_times) / self.settings.planner_hz, 2),
            "steepest_incline_deg": round(math.degrees(self.steepest), 2),
        }


def nearby_obstacles(
    frame: GridFrame,
    obstacles: NDArray[np.bool_],
    straddles: tuple[Straddle, ...],
    position: Array,
    settings: NavigatorSettings,
) -> Array:
    """The band's obstacle points: the obstacle cells within ``obstacle_radius`` of
    ``position`` and, for each straddle that near, the walls of its lane."""
    s = settings
    cells = nearby_cells(frame, obstacles, position, s.obstacle_radius)
    walls = [
        lane_walls(straddle, s.teb.d_min, s.straddle.lane)
        for straddle in straddles
        if np.linalg.norm(straddle.center - position) <= s.obstacle_radius
    ]
    return np.vstack([cells, *walls]) if walls else cells


def nearby_cells(
    frame: GridFrame, occupied: NDArray[np.bool_], position: Array, radius: float
) -> Array:
    """Centres (x, y) [m] of the occupied cells within ``radius`` [m] of ``position``."""
    i, j = np.nonzero(occupied)
    xy = np.column_stack(
        [
            frame.origin[0] + (i + 0.5) * frame.resolution,
            frame.origin[1] + (j + 0.5) * frame.resolution,
        ]
    )
    return xy[np.linalg.norm(xy - position, axis=1) <= radius]


def _stats(seconds: list[float]) -> dict[str, float | None]:
    """Median, p99 and max [ms]."""
    if not seconds:
        return {"median": None, "p99": None, "max": None}
    ms = 1e3 * np.asarray(seconds)
    return {
        "median": round(float(np.median(ms)), 3),
        "p99": round(float(np.percentile(ms, 99)), 3),
        "max": round(float(ms.max()), 3),
    }
