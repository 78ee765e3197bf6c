"""Leg kinematics: where each foot is, and how fast it moves, relative to the base.

Each foot body carries one or more contact sites (two ends of Cassie's line foot, the
centre of a quadruped's ball foot). A foot's *point* is the mean of its sites. With the
base placed at the world origin in the estimated orientation (see
:class:`~ridempc.estimation.joints.JointMap`), Pinocchio gives for foot :math:`i`

.. math::

    d_i = R_{WB}\\, p_{i,B}(q_J) \\quad [m], \\qquad
    w_i = J_i(q)\\, v = R_{WB}\\big(\\omega_B \\times p_{i,B} + J_{i,B}(q_J)\\, \\dot q_J\\big)
    \\quad [m/s],

its position and velocity relative to the base origin in world axes, with :math:`J_i` the
mean of the sites' world-aligned linear Jacobians [m / rad]. The same holds for the IMU
point :math:`d_S, w_S`, so relative to the IMU :math:`p_i - p_S = d_i - d_S` and
:math:`\\dot p_i - \\dot p_S = w_i - w_S`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import mujoco
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.robots.robot import Robot

__all__ = ["Foot", "LegKinematics", "LegReading"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class Foot:
    """One foot.

    Attributes:
        name: Foot body name.
        sites: Its contact sites' Pinocchio frame ids.
        chain_v: v indices of the joints between the base and the foot (root excluded).
    """

    name: str
    sites: tuple[int, ...]
    chain_v: Index


@dataclass(frozen=True)
class LegReading:
    """The feet relative to the base at one tick (world axes, base origin at zero).

    Attributes:
        foot_position: :math:`d_i` [m], shape (feet, 3).
        foot_velocity: :math:`w_i` [m/s], shape (feet, 3).
        site_position: Every contact site, shape (sites, 3) [m], ``site_foot`` order.
        site_velocity: Their velocities, shape (sites, 3) [m/s].
        imu_position: :math:`d_S` [m].
        imu_velocity: :math:`w_S` [m/s].
        site_jacobian: Every contact site's world-aligned linear Jacobian [m / rad], shape
            (sites, 3, nv).
        site_mean: Averages sites into feet [feet x sites].
    """

    foot_position: Array
    foot_velocity: Array
    site_position: Array
    site_velocity: Array
    imu_position: Array
    imu_velocity: Array
    site_jacobian: Array
    site_mean: Array

    @cached_property
    def foot_jacobian(self) -> Array:
        """:math:`J_i` [m / rad], shape (feet, 3, nv): only the torque contact signal
        reads it, so it is averaged when first asked for."""
        sites, nv = self.site_jacobian.shape[0], self.site_jacobian.shape[2]
        jacobian = self.site_mean @ self.site_jacobian.reshape(sites, -1)
        return jacobian.reshape(self.site_mean.shape[0], 3, nv)


@dataclass(frozen=True)
class LegKinematics:
    """The feet of a robot and the kinematics that place them.

    Attributes:
        feet: The feet, in ``robot.params.foot_bodies`` order.
        site_foot: Foot index of every contact site, in ``feet`` then site order.
        imu_frame: Frame id of the IMU site.
    """

    feet: tuple[Foot, ...]
    site_foot: Index
    imu_frame: int

    @classmethod
    def build(cls, robot: Robot, pinocchio: PinocchioRobot) -> LegKinematics:
        """Group the robot's contact sites by foot and find each foot's chain.

        Raises:
            ConfigError: A foot body has no contact site.
        """
        mj, model = robot.mj_model, pinocchio.model
        by_foot: dict[str, list[int]] = {name: [] for name in robot.params.foot_bodies}
        for site in robot.params.contact_sites:
            site_id = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SITE, site)
            body = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, int(mj.site_bodyid[site_id]))
            if body in by_foot:
                by_foot[body].append(pinocchio.frame_id(site))
        feet = []
        for name, sites in by_foot.items():
            if not sites:
                raise ConfigError(f"robot '{robot.name}': foot '{name}' has no contact site")
            joint = model.frames[sites[0]].parentJoint
            chain = [j for j in model.supports[joint] if j > 1]
            chain_v = [
                i for j in chain for i in range(model.idx_vs[j], model.idx_vs[j] + model.nvs[j])
            ]
            feet.append(Foot(name, tuple(sites), np.array(chain_v, dtype=np.int64)))
        site_foot = np.array([i for i, f in enumerate(feet) for _ in f.sites], dtype=np.int64)
        return cls(tuple(feet), site_foot, pinocchio.frame_id(robot.params.imu_site))

    @cached_property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.feet)

    def read(self, model: pin.Model, data: pin.Data, v: Array) -> LegReading:
        """Foot and IMU points relative to the base.

        Args:
            model: The Pinocchio model.
            data: Its data after ``computeJointJacobians`` at the current :math:`q`
                (base at the origin); the placements of the frames read are updated here.
            v: The current velocity (base linear velocity zero).
        """
        frames = self._frames
        points = np.empty((len(frames), 3))
        jacobians = np.empty((len(frames), 3, model.nv))
        for k, frame in enumerate(frames):
            # the frames read, not all of them (updateFramePlacements): reading data.oMf
            # costs more than placing a frame
            points[k] = pin.updateFramePlacement(model, data, frame).translation
            jacobians[k] = pin.getFrameJacobian(model, data, frame, WORLD_ALIGNED)[:3]
        velocities = jacobians @ v
        sites = slice(0, len(frames) - 1)
        return LegReading(
            foot_position=self._site_mean @ points[sites],
            foot_velocity=self._site_mean @ velocities[sites],
            site_position=points[sites],
            site_velocity=velocities[sites],
            imu_position=points[-1],
            imu_velocity=velocities[-1],
            site_jacobian=jacobians[sites],
            site_mean=self._site_mean,
        )

    @cached_property
    def _frames(self) -> tuple[int, ...]:
        """Every contact site's frame, then the IMU's."""
        return tuple(frame for foot in self.feet for frame in foot.sites) + (self.imu_frame,)

    @cached_property
    def _site_mean(self) -> Array:
        """Averages sites into feet: [feet x sites]."""
        counts = np.bincount(self.site_foot, minlength=len(self.feet))
        mean = np.zeros((len(self.feet), len(self.site_foot)))
        mean[self.site_foot, np.arange(len(self.site_foot))] = 1.0 / counts[self.site_foot]
        return mean
