"""The robot's description read by Pinocchio, and MuJoCo <-> Pinocchio coordinates.

Both engines read the same MJCF file and order joints the same way (depth first), but
they differ in two conventions, which :class:`CoordinateMap` converts:

- quaternions: MuJoCo stores (w, x, y, z), Pinocchio (x, y, z, w), for free and ball joints;
- free-joint velocity: MuJoCo's is (linear velocity in the world frame, angular velocity in
  the body frame), Pinocchio's is (linear, angular) both in the body frame, so
  :math:`\\dot q_{mj} = T(q)\\, v_{pin}` with :math:`T = \\mathrm{blkdiag}(R_{WB}, I)`, and the
  joint-space mass matrices relate by :math:`M_{pin} = T^\\top M_{mj} T`.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.robots.robot import Robot
from ridempc.rotations import quaternion_to_matrix

__all__ = ["CoordinateMap", "PinocchioRobot", "build_pinocchio_robot"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class CoordinateMap:
    """Converts configurations and velocities between the two engines for one tree.

    Attributes:
        nq: Configuration size (same in both engines).
        nv: Velocity size (same in both engines).
        free_qpos: qpos address of the free joint.
        ball_qpos: qpos addresses of the ball joints.
    """

    nq: int
    nv: int
    free_qpos: int
    ball_qpos: tuple[int, ...]

    @classmethod
    def from_mujoco(cls, model: mujoco.MjModel) -> CoordinateMap:
        types = model.jnt_type
        free = [int(model.jnt_qposadr[j]) for j in range(model.njnt) if types[j] == 0]
        if len(free) != 1 or free[0] != 0:
            raise ConfigError("the description must have exactly one free joint, on its base")
        balls = tuple(int(model.jnt_qposadr[j]) for j in range(model.njnt) if types[j] == 1)
        return cls(nq=model.nq, nv=model.nv, free_qpos=0, ball_qpos=balls)

    def _quat_addresses(self) -> tuple[int, ...]:
        return (self.free_qpos + 3, *self.ball_qpos)

    def qpos_to_pinocchio(self, qpos: Array) -> Array:
        """MuJoCo qpos -> Pinocchio q (quaternions reordered to x, y, z, w)."""
        q = np.array(qpos, dtype=float)
        for a in self._quat_addresses():
            q[a : a + 4] = qpos[[a + 1, a + 2, a + 3, a]]
        return q

    def qpos_from_pinocchio(self, q: Array) -> Array:
        """Pinocchio q -> MuJoCo qpos."""
        qpos = np.array(q, dtype=float)
        for a in self._quat_addresses():
            qpos[a : a + 4] = q[[a + 3, a, a + 1, a + 2]]
        return qpos

    def velocity_map(self, qpos: Array) -> Array:
        """:math:`T(q)` with :math:`\\dot q_{mj} = T v_{pin}` [nv x nv]."""
        transform = np.eye(self.nv)
        transform[:3, :3] = quaternion_to_matrix(qpos[3:7])
        return transform

    def qvel_to_pinocchio(self, qpos: Array, qvel: Array) -> Array:
        """MuJoCo qvel -> Pinocchio v (base linear velocity into the base frame)."""
        v = np.array(qvel, dtype=float)
        v[:3] = quaternion_to_matrix(qpos[3:7]).T @ qvel[:3]
        return v

    def qvel_from_pinocchio(self, qpos: Array, v: Array) -> Array:
        """Pinocchio v -> MuJoCo qvel."""
        qvel = np.array(v, dtype=float)
        qvel[:3] = quaternion_to_matrix(qpos[3:7]) @ v[:3]
        return qvel


@dataclass(frozen=True)
class PinocchioRobot:
    """Pinocchio's reading of a robot description.

    Attributes:
        model: The kinematic tree with inertias, armature and joint limits.
        constraints: Closed-chain constraints of the description (MJCF ``connect``),
            as Pinocchio constraint models; empty for a pure tree.
        coordinates: MuJoCo <-> Pinocchio conversions for this tree.
        spring_stiffness: Joint stiffness per velocity index [N m / rad] (passive springs).
        spring_reference: Spring rest position per velocity index [rad] (only where stiff).
    """

    model: pin.Model
    constraints: tuple[object, ...]
    coordinates: CoordinateMap
    spring_stiffness: Array
    spring_reference: Array

    def frame_id(self, name: str) -> int:
        if not self.model.existFrame(name):
            raise ConfigError(f"Pinocchio model '{self.model.name}' has no frame '{name}'")
        return int(self.model.getFrameId(name))


def build_pinocchio_robot(robot: Robot) -> PinocchioRobot:
    """Read the robot's MJCF with Pinocchio and check its joints match MuJoCo's.

    Torque limits (MJCF actuators) are copied into ``model.effortLimit`` from the same
    file as MuJoCo compiled it, so both sides use one set of limits.
    """
    path = str(robot.mjcf_path)
    model, point_constraints, frame_constraints = pin.buildModelAndConstraintsFromMJCF(path)
    mj = robot.mj_model
    mj_names = [mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(mj.njnt)]
    pin_names = list(model.names)[1:]
    if pin_names != mj_names or model.nv != mj.nv or model.nq != mj.nq:
        raise ConfigError(
            f"{path}: Pinocchio and MuJoCo read different trees "
            f"(Pinocchio joints {pin_names}, MuJoCo joints {mj_names})"
        )
    for motor in robot.motors:
        idx = model.joints[model.getJointId(motor.joint)].idx_v
        model.effortLimit[idx] = motor.torque_limit
        model.velocityLimit[idx] = motor.speed_limit
    stiffness = np.zeros(mj.nv)
    reference = np.zeros(mj.nv)
    for j in range(mj.njnt):
        if mj.jnt_stiffness[j] > 0.0:
            stiffness[mj.jnt_dofadr[j]] = mj.jnt_stiffness[j]
            reference[mj.jnt_dofadr[j]] = mj.qpos_spring[mj.jnt_qposadr[j]]
    constraints = tuple(point_constraints) + tuple(frame_constraints)
    return PinocchioRobot(
        model=model,
        constraints=constraints,
        coordinates=CoordinateMap.from_mujoco(mj),
        spring_stiffness=stiffness,
        spring_reference=reference,
    )
