"""The course's judge: true clearance to the boxes and collisions, from the simulator.

Like the fall detector it reads the true state, and nothing it reads reaches the planner.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ridempc.sim.contact_pairs import collision_geoms
from ridempc.sim.scene import Scene

__all__ = ["CourseJudge"]

JUDGE_HZ: float = 20.0  # [Hz] a box touched for less than 50 ms is still in contact at a check
DISTMAX: float = 2.0  # [m] clearances beyond this are not computed (nothing is that close)


class CourseJudge:
    """Records the smallest distance between the rider (and board) and the boxes, and
    each new contact with a box.

    Args:
        scene: The scene.
        obstacles: Geom ids of the boxes.
    """

    def __init__(self, scene: Scene, obstacles: list[int]) -> None:
        self._model = scene.model
        self._every = max(1, round(scene.physics_hz / JUDGE_HZ))
        self._hz = scene.physics_hz
        self._ours = sorted(collision_geoms(scene.model, scene.rider_bodies | scene.board_bodies))
        self._obstacles = obstacles
        self._is_obstacle = np.zeros(scene.model.ngeom, dtype=bool)
        self._is_obstacle[obstacles] = True
        self.min_clearance = float("inf")
        self.collisions: list[dict[str, object]] = []
        self._touching: set[tuple[int, int]] = set()
        self._fromto = np.zeros(6)

    def __call__(self, t: float, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        if round(t * self._hz) % self._every:
            return
        for box in self._obstacles:
            for geom in self._ours:
                d = mujoco.mj_geomDistance(model, data, geom, box, DISTMAX, self._fromto)
                self.min_clearance = min(self.min_clearance, d)
        geoms = data.contact.geom[: data.ncon]
        hits = geoms[self._is_obstacle[geoms].any(axis=1)]
        touching = {(int(min(a, b)), int(max(a, b))) for a, b in hits}
        for pair in sorted(touching - self._touching):
            box, other = (pair[0], pair[1]) if self._is_obstacle[pair[0]] else (pair[1], pair[0])
            self.collisions.append(
                {
                    "t": round(t, 3),
                    "obstacle": mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, box),
                    "body": mujoco.mj_id2name(
                        model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[other])
                    ),
                }
            )
        self._touching = touching
