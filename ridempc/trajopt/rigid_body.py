"""The single-rigid-body-plus-full-kinematics (SRBKM) robot of the skateboard paper, eq. (1)-(3).

The trunk is one rigid body carrying the robot's total mass :math:`m_R` and its composite
(centroidal) inertia :math:`I_R`, both read from Pinocchio at a reference stance (the
robot's riding keyframe); the legs are massless, but their kinematics are exact: the feet
follow the joint angles :math:`q_j` through :func:`ridempc.trajopt.kinematics.frame_kinematics`,
generated from Pinocchio's reading of the same MJCF. State and input:

.. math:: x_R = [p_R, \\theta_R, v_R, \\omega_R, q_j], \\qquad u_R = [f_i, \\dot q_j]
          \\quad (1), (2)

with :math:`p_R` the centre of mass [m] and :math:`v_R` its velocity [m/s] in the world,
:math:`\\theta_R` Z-Y-X Euler angles [rad], :math:`\\omega_R` the body-frame angular velocity
[rad/s], and the dynamics

.. math::

    \\dot p_R = v_R, \\quad \\dot\\theta_R = T(\\theta_R)\\,\\omega_R, \\quad
    \\dot v_R = \\frac{1}{m_R}\\sum_i f_i + g, \\\\
    \\dot\\omega_R = I_R^{-1}\\Big(R_R^\\top \\sum_i r_{R_i} \\times f_i
                    - \\omega_R \\times I_R\\,\\omega_R\\Big), \\quad \\dot q_j = \\dot q_j
    \\quad (3)

where :math:`f_i` [N] are the contact forces on the robot in the world frame and
:math:`r_{R_i}` the world-frame vectors from the centre of mass to the contact points. The
centre of mass sits at a fixed point of the trunk frame (its place at the reference stance):
a foot's world position is :math:`p_R + R_R\\,(p^{trunk}_i(q_j) - c^{trunk})`.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType
from typing import Any

import casadi as ca
import mujoco
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.gravity import GRAVITY
from ridempc.robots.motor_curve import TorqueSpeedCurve
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.trajopt.kinematics import frame_kinematics
from ridempc.trajopt.rotations import euler_rate_map, euler_zyx_matrix

__all__ = [
    "GRAVITY",
    "RigidBodyRobot",
    "build_rigid_body_robot",
    "feet_world",
    "rigid_body_rates",
    "rigid_body_state_names",
]

Array = NDArray[np.float64]


def rigid_body_state_names(base: str) -> tuple[str, ...]:
    """Names of the single rigid body's 12 states of eq. (1), in order: centre of mass [m],
    the ``base`` body's Z-Y-X angles [rad], CoM velocity [m/s], body angular rate [rad/s]."""
    return (
        "com_x",
        "com_y",
        "com_z",
        f"{base}_roll",
        f"{base}_pitch",
        f"{base}_yaw",
        "vx",
        "vy",
        "vz",
        "wx",
        "wy",
        "wz",
    )


_FREE_FLYER_IDENTITY = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])


@dataclass(frozen=True)
class RigidBodyRobot:
    """A robot reduced to the SRBKM model (checked against Pinocchio in the tests).

    Attributes:
        name: Robot name.
        mass: Total mass :math:`m_R` [kg].
        inertia: Composite rotational inertia :math:`I_R` about the centre of mass, in the
            trunk frame, at the reference stance [kg m^2] (3 x 3).
        com_in_trunk: Centre of mass in the trunk frame at the reference stance [m] (3,).
        joints: Names of the actuated joints, the order of :math:`q_j`.
        q_reference: Joint angles of the reference stance [rad].
        q_lower: Lower joint limits [rad].
        q_upper: Upper joint limits [rad].
        torque_limit: Joint torque limits [N m] (the curves' peaks).
        speed_limit: Joint speed limits [rad/s] (the curves' no-load speeds).
        curve: The motors' torque-speed curves, in the order of :math:`q_j`.
        feet: Contact sites, the order of the feet.
        foot_radius: Distance from each contact site to its contact point [m] (a sphere
            foot's radius; 0 for a site on the sole).
        legs: For each foot, the indices into :math:`q_j` of the joints that move it.
        feet_in_trunk: CasADi function :math:`q_j \\mapsto (p^{trunk}_1, \\dots)`: contact
            sites in the trunk frame [m], one 3 x 1 output per foot.
        q_full_reference: Pinocchio configuration of the reference stance, base at the origin.
        base: The base body (the robot description's ``base_body``), whose Z-Y-X angles
            the states carry (:func:`rigid_body_state_names`).
    """

    name: str
    mass: float
    inertia: Array
    com_in_trunk: Array
    joints: tuple[str, ...]
    q_reference: Array
    q_lower: Array
    q_upper: Array
    torque_limit: Array
    speed_limit: Array
    curve: TorqueSpeedCurve
    feet: tuple[str, ...]
    foot_radius: Array
    legs: tuple[tuple[int, ...], ...]
    feet_in_trunk: ca.Function
    q_full_reference: Array
    base: str

    @property
    def n_joints(self) -> int:
        return len(self.joints)

    @property
    def n_feet(self) -> int:
        return len(self.feet)

    def foot_jacobian(self, q_joints: Any, foot: int) -> Any:
        """:math:`\\partial p^{trunk}_i / \\partial q_j` of one foot (3 x n_joints)."""
        return ca.jacobian(self.feet_in_trunk(q_joints)[foot], q_joints)


def _site_to_contact(model: mujoco.MjModel, site: str) -> float:
    """Distance from a contact site to the contact point: a sphere's radius if the site is
    at the centre of a sphere geom of its body, else 0."""
    site_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
    body = model.site_bodyid[site_id]
    for g in range(model.ngeom):
        if (
            model.geom_bodyid[g] == body
            and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE
            and np.allclose(model.geom_pos[g], model.site_pos[site_id])
        ):
            return float(model.geom_size[g, 0])
    return 0.0


def build_rigid_body_robot(robot: Robot, keyframe: str) -> RigidBodyRobot:
    """Reduce ``robot`` to the SRBKM model at ``keyframe`` (its riding stance).

    Mass, composite inertia and centre of mass come from Pinocchio (``ccrba``) with the
    base at the origin; the feet's kinematics from :func:`frame_kinematics`. Joints that are
    not actuated (Cassie's springs and four-bar) stay at their keyframe values.

    Raises:
        ConfigError: The keyframe is missing or the description has no free base.
    """
    pinned = build_pinocchio_robot(robot)
    model = pinned.model
    data = model.createData()
    q_full = pinned.coordinates.qpos_to_pinocchio(robot.keyframe_qpos(keyframe))
    if model.joints[1].shortname() != "JointModelFreeFlyer":
        raise ConfigError(f"{robot.mjcf_path}: the SRBKM model needs a free-flying base")
    q_full[:7] = _FREE_FLYER_IDENTITY
    pin.ccrba(model, data, q_full, np.zeros(model.nv))
    inertia = np.array(data.Ig.inertia, dtype=float)
    com = np.array(data.com[0], dtype=float)

    motor_joints = tuple(m.joint for m in robot.motors)
    q_index = [model.joints[model.getJointId(j)].idx_q for j in motor_joints]
    v_index = [model.joints[model.getJointId(j)].idx_v for j in motor_joints]
    q_joints = ca.SX.sym("q_joints", len(motor_joints))
    q_sym = ca.SX(ca.DM(q_full))
    for k, i in enumerate(q_index):
        q_sym[i] = q_joints[k]
    feet = tuple(robot.params.contact_sites)
    kinematics = frame_kinematics(model, list(feet))
    outputs = kinematics(q_sym)
    positions = [outputs[2 * k] for k in range(len(feet))]
    feet_in_trunk = ca.Function("feet_in_trunk", [q_joints], positions)

    legs = []
    for site in feet:
        joint = model.frames[model.getFrameId(site)].parentJoint
        chain = []
        while joint > 1:  # stop at the free flyer
            name = model.names[joint]
            if name in motor_joints:
                chain.append(motor_joints.index(name))
            joint = model.parents[joint]
        legs.append(tuple(sorted(chain)))

    mj = robot.mj_model
    return RigidBodyRobot(
        name=robot.name,
        mass=float(pin.computeTotalMass(model)),
        inertia=inertia,
        com_in_trunk=com,
        joints=motor_joints,
        q_reference=np.array([q_full[i] for i in q_index]),
        q_lower=np.array([model.lowerPositionLimit[i] for i in q_index]),
        q_upper=np.array([model.upperPositionLimit[i] for i in q_index]),
        torque_limit=np.array([model.effortLimit[i] for i in v_index]),
        speed_limit=np.array([model.velocityLimit[i] for i in v_index]),
        curve=TorqueSpeedCurve.of(robot.motors),
        feet=feet,
        foot_radius=np.array([_site_to_contact(mj, s) for s in feet]),
        legs=tuple(legs),
        feet_in_trunk=feet_in_trunk,
        q_full_reference=q_full,
        base=robot.params.base_body,
    )


def feet_world(
    robot: RigidBodyRobot, com: Any, euler: Any, q_joints: Any, xp: ModuleType = ca
) -> list[Any]:
    """World positions of the contact sites: :math:`p_R + R_R (p^{trunk}_i(q_j) - c^{trunk})`.

    Args:
        robot: The SRBKM robot.
        com: Centre of mass :math:`p_R` [m].
        euler: Z-Y-X Euler angles :math:`\\theta_R` [rad].
        q_joints: Joint angles [rad].
        xp: ``casadi`` (symbolic) or ``numpy`` (numbers).
    """
    rotation = euler_zyx_matrix(euler[0], euler[1], euler[2], xp)
    offsets = robot.feet_in_trunk(q_joints)
    if xp is np:
        return [
            np.asarray(com).ravel() + rotation @ (np.asarray(o).ravel() - robot.com_in_trunk)
            for o in offsets
        ]
    return [com + rotation @ (o - ca.DM(robot.com_in_trunk)) for o in offsets]


def rigid_body_rates(
    robot: RigidBodyRobot,
    state: Any,
    forces: list[Any],
    points: list[Any],
    joint_rates: Any,
) -> Any:
    """Eq. (3): :math:`\\dot x_R` of the SRBKM robot (CasADi).

    Args:
        robot: The SRBKM robot.
        state: :math:`x_R = [p_R, \\theta_R, v_R, \\omega_R, q_j]` (12 + n_joints).
        forces: Contact forces on the robot, world frame [N], one 3-vector per contact.
        points: World contact points where they act [m], one 3-vector per contact.
        joint_rates: :math:`\\dot q_j` [rad/s].

    Returns:
        :math:`\\dot x_R`, same layout as ``state``.
    """
    euler = state[3:6]
    velocity = state[6:9]
    omega = state[9:12]
    inertia = ca.DM(robot.inertia)
    inertia_inverse = ca.DM(np.linalg.inv(robot.inertia))
    rotation = euler_zyx_matrix(euler[0], euler[1], euler[2], ca)
    total_force = ca.DM.zeros(3)
    moment = ca.DM.zeros(3)
    for f, r in zip(forces, points, strict=True):
        total_force = total_force + f
        moment = moment + ca.cross(r - state[0:3], f)
    acceleration = total_force / robot.mass + ca.DM([0.0, 0.0, -GRAVITY])
    angular = inertia_inverse @ (rotation.T @ moment - ca.cross(omega, inertia @ omega))
    return ca.vertcat(
        velocity,
        euler_rate_map(euler[0], euler[1], ca) @ omega,
        acceleration,
        angular,
        joint_rates,
    )
