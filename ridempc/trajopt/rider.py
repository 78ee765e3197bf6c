"""A simplified biped rider for the wheeled boards: one rigid body on massless telescoping legs.

For Cassie on the Hovershoes or the Segway the trajectories are built on the board's reduced
model, and the rider is reduced further than the quadruped's SRBKM model: the pelvis is one
rigid body with Cassie's total mass and composite inertia at its riding keyframe (read from
Pinocchio, eq. 3 of the skateboard paper without the joint states), and each leg is a
massless strut from its hip (the hip-pitch joint, a fixed point of the pelvis) to its foot,
whose length stays within a band around the keyframe's, so that the feet stay where the
platforms carry them. Each foot touches its platform at the ends of its line foot (toe front
and back), so it can press harder at the toe or the heel (pitch torque) and twist (yaw
torque), as Cassie does on the Hovershoes (hovershoe paper, eq. 9).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.trajopt.rigid_body import RigidBodyRobot, build_rigid_body_robot

__all__ = ["RiderModel", "build_rider"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class RiderModel:
    """The simplified rider.

    Attributes:
        body: The rigid body (mass, inertia, centre of mass in the pelvis frame).
        contacts: Contact sites (toe front / back of each foot).
        foot_of_contact: For each contact, the index of its foot.
        hips: Hip points in the pelvis frame, relative to the centre of mass [m], one per foot.
        feet_from_com: The contacts in the pelvis frame, relative to the centre of mass, at
            the keyframe [m] (n_contacts x 3).
        leg_length: Hip-to-foot (mid-sole) distance at the keyframe, per foot [m].
        leg_range: Allowed leg length as fractions of ``leg_length`` (shortest, longest).
    """

    body: RigidBodyRobot
    contacts: tuple[str, ...]
    foot_of_contact: tuple[int, ...]
    hips: Array
    feet_from_com: Array
    leg_length: Array
    leg_range: tuple[float, float]

    @property
    def n_feet(self) -> int:
        return len(self.hips)

    @property
    def n_contacts(self) -> int:
        return len(self.contacts)


def build_rider(
    robot: Robot, keyframe: str, hip_joints: tuple[str, ...], leg_range: tuple[float, float]
) -> RiderModel:
    """The simplified rider of ``robot`` at ``keyframe``.

    Args:
        robot: The robot (a biped).
        keyframe: Its riding keyframe.
        hip_joints: Per foot, the joint whose origin is the hip (left foot first).
        leg_range: Shortest and longest leg as fractions of the keyframe's.

    Raises:
        ConfigError: A hip joint is missing, or a contact site's foot cannot be told.
    """
    body = build_rigid_body_robot(robot, keyframe)
    pinned = build_pinocchio_robot(robot)
    model, data = pinned.model, pinned.model.createData()
    pin.framesForwardKinematics(model, data, body.q_full_reference)
    hips = []
    for joint in hip_joints:
        if not model.existJointName(joint):
            raise ConfigError(f"{robot.mjcf_path}: no joint '{joint}' for a hip")
        hips.append(np.array(data.oMi[model.getJointId(joint)].translation) - body.com_in_trunk)
    feet = np.array([np.asarray(f).ravel() for f in body.feet_in_trunk(body.q_reference)])
    feet = feet - body.com_in_trunk
    # A contact belongs to the hip on its side (same sign of y).
    foot_of_contact = []
    for contact, point in zip(body.feet, feet, strict=True):
        sides = [k for k, hip in enumerate(hips) if np.sign(hip[1]) == np.sign(point[1])]
        if len(sides) != 1:
            raise ConfigError(f"contact '{contact}' cannot be assigned to one hip")
        foot_of_contact.append(sides[0])
    lengths = np.array(
        [
            np.linalg.norm(
                np.mean([feet[i] for i, f in enumerate(foot_of_contact) if f == k], axis=0)
                - hips[k]
            )
            for k in range(len(hips))
        ]
    )
    return RiderModel(
        body=body,
        contacts=body.feet,
        foot_of_contact=tuple(foot_of_contact),
        hips=np.array(hips),
        feet_from_com=feet,
        leg_length=lengths,
        leg_range=leg_range,
    )
