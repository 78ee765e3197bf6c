"""Fall detection: the base too low, or a body other than the feet touching the ground."""

from __future__ import annotations

import mujoco

from ridempc.sim.scene import Scene

__all__ = ["FallDetector"]


class FallDetector:
    """Checks the true state for a fall (the judge's view, never shown to controllers).

    A fall is either the base origin below ``fall_height`` [m] over the ground, or a
    contact between the ground and a robot body that is not a foot.
    """

    def __init__(self, scene: Scene) -> None:
        self._base = scene.base_body
        self._fall_height = scene.robot.params.fall_height
        self._forbidden = scene.robot_bodies - scene.foot_bodies
        self._ground = scene.ground_geoms
        self._names = {
            b: mujoco.mj_id2name(scene.model, mujoco.mjtObj.mjOBJ_BODY, b) for b in self._forbidden
        }

    def check(self, model: mujoco.MjModel, data: mujoco.MjData) -> str | None:
        """The reason of a fall now, or None."""
        height = data.xpos[self._base, 2]
        if height < self._fall_height:
            return f"base height {height:.3f} m below {self._fall_height:.3f} m"
        for i in range(data.ncon):
            contact = data.contact[i]
            g1, g2 = contact.geom[0], contact.geom[1]
            for ground, other in ((g1, g2), (g2, g1)):
                if ground in self._ground:
                    body = int(model.geom_bodyid[other])
                    if body in self._forbidden:
                        return f"'{self._names[body]}' touched the ground"
        return None
