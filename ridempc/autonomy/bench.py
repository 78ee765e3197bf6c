"""``ridempc navigate --bench``: the planners' update times on the library's courses.

For each course, on the map rasterised from its boxes (what the camera builds, without its
noise, each cell with its box's height): the global replan as the navigator runs it
(:func:`~ridempc.autonomy.global_plan.plan_global`: costmap, straddles, Dijkstra), repeated,
and the search alone on the pure-Python :mod:`heapq` reference; and the timed elastic band at every
``STEP`` along the global path, warm-started from the last update as in a ride. Wall-clock
figures depend on the machine's load: compare them on an idle machine.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from ridempc.autonomy.costmap import inflate
from ridempc.autonomy.course import course_names, resolve_course
from ridempc.autonomy.dijkstra import plan_heapq
from ridempc.autonomy.global_plan import plan_global
from ridempc.autonomy.navigate import course_map
from ridempc.autonomy.navigator import NavigatorSettings, nearby_obstacles
from ridempc.autonomy.teb import LOOK_AHEAD, TebPlanner
from ridempc.io import atomic_write_json

__all__ = ["bench_planners"]

REPEATS: int = 20  # global plans per course
HEAPQ_REPEATS: int = 3  # the reference is slow
STEP: float = 0.1  # [m] between TEB updates along the path: 10 Hz at 1 m/s


def _ms(seconds: list[float]) -> dict[str, float]:
    ms = 1e3 * np.asarray(seconds)
    return {
        "min": round(float(ms.min()), 3),
        "median": round(float(np.median(ms)), 3),
        "p99": round(float(np.percentile(ms, 99)), 3),
    }


def bench_course(name: str) -> dict[str, Any]:
    """The planners' times on one course [ms]."""
    settings = NavigatorSettings()
    course = resolve_course(name).in_start_frame()
    frame, occupied, height = course_map(course)
    observed = np.ones(frame.shape, dtype=bool)
    start, goal = np.asarray(course.start[:2]), np.asarray(course.goal)
    plans, heapq_plans = [], []
    path = np.zeros((0, 2))
    for _ in range(REPEATS):
        began = time.perf_counter()
        planned = plan_global(frame, occupied, height, observed, start, goal, settings)
        plans.append(time.perf_counter() - began)
    path, straddles = planned.path, planned.straddles
    obstacles = occupied.copy()
    for straddle in straddles:
        obstacles &= ~straddle.cells
    for _ in range(HEAPQ_REPEATS):
        began = time.perf_counter()
        costmap = inflate(frame, occupied, settings.inscribed, settings.decay)
        plan_heapq(costmap.coarsened(settings.global_coarsening), start, goal)
        heapq_plans.append(time.perf_counter() - began)
    teb = TebPlanner(settings.teb)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    teb_times, failures = [], 0
    for s in np.arange(0.0, arc[-1] - 0.3, STEP):
        here = _along(path, arc, s)
        ahead = _along(path, arc, min(arc[-1], s + LOOK_AHEAD))
        heading = _heading(path, arc, s)
        band = teb.solve(
            np.array([*here, heading]),
            np.array([*ahead, _heading(path, arc, min(arc[-1], s + LOOK_AHEAD))]),
            nearby_obstacles(frame, obstacles, straddles, here, settings),
            speed=settings.teb.v_max,
        )
        teb_times.append(band.solve_time)
        failures += not band.success
    return {
        "course": name,
        "cells": int(occupied.size),
        "global_plan_ms": _ms(plans),
        "global_plan_heapq_ms": _ms(heapq_plans),
        "teb_ms": _ms(teb_times),
        "teb_updates": len(teb_times),
        "teb_failures": failures,
        "straddles": len(straddles),
    }


def _along(path: np.ndarray, arc: np.ndarray, s: float) -> np.ndarray:
    return np.array([np.interp(s, arc, path[:, 0]), np.interp(s, arc, path[:, 1])])


def _heading(path: np.ndarray, arc: np.ndarray, s: float) -> float:
    a, b = _along(path, arc, max(0.0, s - 0.15)), _along(path, arc, min(arc[-1], s + 0.15))
    return math.atan2(b[1] - a[1], b[0] - a[0])


def bench_planners(course: str | None, json_path: Path | None = None) -> list[dict[str, Any]]:
    """Time the planners on ``course`` (default: every library course); print a table."""
    names = [course] if course is not None else list(course_names())
    for name in names:
        resolve_course(name)  # bad input before any timing
    rows = []
    print(
        f"{'course':<12} {'cells':>7} {'global median/p99':>18} {'heapq median':>13} "
        f"{'TEB median/p99':>15} {'updates':>8}"
    )
    for name in names:
        row = bench_course(name)
        rows.append(row)
        g, h, t = row["global_plan_ms"], row["global_plan_heapq_ms"], row["teb_ms"]
        print(
            f"{row['course']:<12} {row['cells']:>7} {g['median']:>8.1f}/{g['p99']:<8.1f} ms "
            f"{h['median']:>10.1f} ms {t['median']:>6.1f}/{t['p99']:<6.1f} ms "
            f"{row['teb_updates']:>6} ({row['teb_failures']} failed)"
        )
    if json_path is not None:
        atomic_write_json(json_path, {"courses": rows})
    return rows
