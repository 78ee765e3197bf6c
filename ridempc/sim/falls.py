"""Fall detection, from the judge's true-state view (never shown to controllers).

The rider fell when its base is below ``fall_height`` [m] over its starting support, or when
one of its bodies that is not a foot touches the ground (for a dead weight: any of it).
The board fell when one of its bodies other than the wheels touches the ground. On a board,
a rider's foot on the ground is a fall too (it stepped off), unless the ride puts a foot
there on purpose (a skateboard push-off, ``feet_on_ground``); even then, every foot on the
ground at once is stepping off.
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
        self._names = {
            b: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in self._forbidden
        }
        # lookup tables, to judge all the contacts at once rather than one at a time
        self._is_ground = np.zeros(model.ngeom, dtype=bool)
        self._is_ground[list(scene.ground_geoms)] = True
        self._is_forbidden = np.zeros(model.nbody, dtype=bool)
        self._is_forbidden[list(self._forbidden)] = True

    def check(self, model: mujoco.MjModel, data: mujoco.MjData) -> str | None:
        """The reason of a fall now, or None."""
        if self._fall_height is not None:
            height = data.xpos[self._base, 2]
            if height < self._fall_height:
                return f"base height {height:.3f} m below {self._fall_height:.3f} m"
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
