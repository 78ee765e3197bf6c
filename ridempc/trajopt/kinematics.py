"""Forward kinematics in CasADi, generated from the Pinocchio model of the same MJCF.

Pinocchio's PyPI wheel has no ``pinocchio.casadi``, so the trajectory optimisation builds its
own symbolic kinematics by walking Pinocchio's tree: for each joint on the way to a frame,

.. math:: {}^{0}T_{i} = {}^{0}T_{\\lambda(i)}\\; {}^{\\lambda(i)}T_{i}^{\\text{placement}}\\;
          T_{i}(q_i),

with :math:`T_i(q_i)` a rotation about the joint axis for revolute joints, the quaternion
rotation for spherical joints and the full pose for the free flyer. Configurations use
Pinocchio's convention (quaternions x, y, z, w). Because the placements, axes and frame
offsets are read from the Pinocchio model at build time, the symbolic kinematics cannot
drift from the description; ``tests/test_trajopt_kinematics.py`` checks them against
``pinocchio.framesForwardKinematics``.
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np
import pinocchio as pin

from ridempc.errors import ConfigError

__all__ = ["frame_kinematics"]

_AXES = {
    "JointModelRX": (1.0, 0.0, 0.0),
    "JointModelRY": (0.0, 1.0, 0.0),
    "JointModelRZ": (0.0, 0.0, 1.0),
}


def _quaternion_matrix(x: Any, y: Any, z: Any, w: Any) -> ca.SX:
    """Rotation matrix of a unit quaternion (x, y, z, w) [-]."""
    return ca.vertcat(
        ca.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        ca.horzcat(2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        ca.horzcat(2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
    )


def _axis_rotation(axis: np.ndarray, angle: Any) -> ca.SX:
    """Rodrigues' formula :math:`R = I + \\sin q\\, [a]_\\times + (1 - \\cos q)[a]_\\times^2`."""
    skew = ca.DM([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return ca.DM.eye(3) + ca.sin(angle) * skew + (1 - ca.cos(angle)) * (skew @ skew)


def _joint_motion(joint: Any, q: ca.SX) -> tuple[Any, Any]:
    """Rotation and translation of one joint at configuration ``q``."""
    kind = joint.shortname()
    i = joint.idx_q
    if kind in _AXES:
        return _axis_rotation(np.array(_AXES[kind]), q[i]), ca.DM.zeros(3)
    if kind == "JointModelRevoluteUnaligned":
        return _axis_rotation(np.asarray(joint.extract().axis), q[i]), ca.DM.zeros(3)
    if kind == "JointModelSpherical":
        return _quaternion_matrix(q[i], q[i + 1], q[i + 2], q[i + 3]), ca.DM.zeros(3)
    if kind == "JointModelFreeFlyer":
        return _quaternion_matrix(q[i + 3], q[i + 4], q[i + 5], q[i + 6]), q[i : i + 3]
    raise ConfigError(f"joint type {kind} is not supported by the CasADi kinematics")


def frame_kinematics(model: pin.Model, frames: list[str], name: str = "frames") -> ca.Function:
    """A CasADi function ``q -> (p_1, R_1, p_2, R_2, ...)`` for the named frames.

    Args:
        model: Pinocchio model (of the robot description).
        frames: Frame names (sites or bodies of the MJCF).
        name: Name of the CasADi function.

    Returns:
        Function of Pinocchio's configuration ``q`` [nq] returning, for each frame, its
        world position [m] (3 x 1) and rotation (3 x 3).
    """
    q = ca.SX.sym("q", model.nq)
    cache: dict[int, tuple[Any, Any]] = {0: (ca.DM.eye(3), ca.DM.zeros(3))}

    def joint_pose(j: int) -> tuple[Any, Any]:
        if j not in cache:
            parent_r, parent_p = joint_pose(model.parents[j])
            placement = model.jointPlacements[j]
            r_fixed = parent_r @ ca.DM(placement.rotation)
            p_fixed = parent_p + parent_r @ ca.DM(placement.translation)
            r_joint, p_joint = _joint_motion(model.joints[j], q)
            cache[j] = (r_fixed @ r_joint, p_fixed + r_fixed @ p_joint)
        return cache[j]

    outputs = []
    for frame_name in frames:
        if not model.existFrame(frame_name):
            raise ConfigError(f"Pinocchio model has no frame '{frame_name}'")
        frame = model.frames[model.getFrameId(frame_name)]
        rot, pos = joint_pose(frame.parentJoint)
        outputs += [
            pos + rot @ ca.DM(frame.placement.translation),
            rot @ ca.DM(frame.placement.rotation),
        ]
    return ca.Function(name, [q], outputs)
