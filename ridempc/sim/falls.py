"""Fall detection, from the judge's true-state view (never shown to controllers).

The rider fell when its base is below ``fall_height`` [m] over its support, or when
one of its bodies that is not a foot touches the ground (for a dead weight: any of it).
The board fell when one of its bodies other than the wheels touches the ground. On a board,
a rider's foot on the ground is a fall too (it stepped off), unless the ride puts a foot
there on purpose (a skateboard push-off, ``feet_on_ground``); even then, every foot on the
ground at once is stepping off.

On terrain the support is the starting one moved with the ground under the rider: the
lowest of the terrain's heights under the base and under each board root (a step down
passed by the base and not yet by the shoes does not count as a fall).
"""

from __future__ import annotations

import mujoco
import numpy as np

from ridempc.sim.scene import Scene

__all__ = ["FallDetector"]


class FallDetector:
    """Judges falls on ``scene``; with ``feet_on_ground`` a rider's feet may touch the
    ground even on a board (a push-off)."""

    def __init__(self, scene: Scene, feet_on_ground: bool = False) -> None:
        model = scene.model
        self._base = scene.base_body
        robot = scene.robot
        self._fall_height = (
            scene.support_height + robot.params.fall_height if robot is not None else None
        )
        on_board = scene.board is not None and not feet_on_ground
        allowed = frozenset() if on_board else scene.foot_bodies
        # a push-off puts a foot down, never all of them
        self._all_feet = scene.foot_bodies if scene.board is not None and feet_on_ground else None
        self._forbidden = {b: "rider" for b in scene.rider_bodies - allowed} | {
            b: "board" for b in scene.board_bodies - scene.board_ground_bodies
        }
        self._terrain = scene.terrain
        self._roots = (self._base, *scene.board_roots)
        self._names = {
            b: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in self._forbidden
        }
        # lookup tables, to judge all the contacts at once rather than one at a time
        self._is_ground = np.zeros(model.ngeom, dtype=bool)
        self._is_ground[list(scene.ground_geoms)] = True
        self._is_forbidden = np.zeros(model.nbody, dtype=bool)
        self._is_forbidden[list(self._forbidden)] = True

    def _ground_under_rider(self, data: mujoco.MjData) -> float:
        """Height of the terrain under the rider [m] (0: flat ground, the start's)."""
        if self._terrain is None:
            return 0.0
        return min(self._terrain.height_at(*data.xpos[b, :2]) for b in self._roots)

    def check(self, model: mujoco.MjModel, data: mujoco.MjData) -> str | None:
        """The reason of a fall now, or None."""
        if self._fall_height is not None:
            height = data.xpos[self._base, 2]
            limit = self._fall_height + self._ground_under_rider(data)
            if height < limit:
                return f"base height {height:.3f} m below {limit:.3f} m"
        geoms = data.contact.geom[: data.ncon]
        # per contact, the body of each geom touching the ground: (g1 on ground -> g2's, then
        # g2 on ground -> g1's), contact by contact
        others = geoms[:, ::-1][self._is_ground[geoms]]
        bodies = model.geom_bodyid[others]
        forbidden = self._is_forbidden[bodies]
        if forbidden.any():
            body = int(bodies[forbidden.argmax()])
            return f"{self._forbidden[body]} body '{self._names[body]}' touched the ground"
        if self._all_feet and set(bodies.tolist()) >= self._all_feet:
            return "rider stepped off the board: every foot on the ground"
        return None
