"""Cassie's inverse statics: the motor torques that hold given ground forces at the feet.

With the feet loaded by ground forces :math:`f_i` at points :math:`c_i` (each foot's centre
of pressure), the joint torques that balance gravity and these forces are

.. math:: \\tau = G^\\top \\Big( g(q) - \\sum_i J_{c_i}(q)^\\top f_i \\Big)

[N m], where :math:`g(q)` is the generalised gravity of the floating-base model,
:math:`J_{c_i} = J_{lin} - [c_i - o_i]_\\times J_{ang}` the Jacobian of the point
:math:`c_i` on foot :math:`i` (origin :math:`o_i`), and :math:`G` maps the motors to the
tree's joints with the springs locked and the tarsus driven by the knee through the
four-bar (eq. 3 of the Segway paper, :math:`\\dot q_{tarsus} = -\\dot q_{knee}`), so that the
knee motor's row is the knee's minus the tarsus's. The four-bar's constraint force does no
work along :math:`G`, which is why it drops out. Only the motor rows are used: the base rows
balance only when the centre of pressure is under the centre of mass, and the standing
controller moves the centre of pressure on purpose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.baselines.cassie_kinematics import SIDES, CassieKinematics, LegIndices
from ridempc.rotations import skew

__all__ = ["FootLoad", "StandingStatics"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class FootLoad:
    """The ground's force on one foot.

    Attributes:
        point: Where it acts (the foot's centre of pressure), world axes, pelvis origin [m].
        force: The force, world axes [N].
    """

    point: Array
    force: Array


class StandingStatics:
    """Motor torques for given foot loads (feedforward of the standing controller).

    Args:
        kinematics: Cassie's kinematics (model, joint and frame indices).
    """

    def __init__(self, kinematics: CassieKinematics) -> None:
        self.kinematics = kinematics
        self._data = kinematics.model.createData()
        self.n_motors = len(kinematics.robot.motors)

    def generalised_torque(self, q: Array, loads: dict[str, FootLoad]) -> Array:
        """:math:`g(q) - \\sum_i J_{c_i}^\\top f_i` over all joints [N m or N]."""
        model, data = self.kinematics.model, self._data
        tau = np.array(pin.computeGeneralizedGravity(model, data, q))
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for side, load in loads.items():
            frame = self.kinematics.legs[side].foot_frame
            jac = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
            lever = np.asarray(load.point) - data.oMf[frame].translation
            point_jac = jac[:3] - skew(lever) @ jac[3:]
            tau -= point_jac.T @ np.asarray(load.force)
        return tau

    def motor_torques(self, q: Array, loads: dict[str, FootLoad]) -> Array:
        """:math:`G^\\top (g - \\sum_i J_{c_i}^\\top f_i)` at the motors, actuator order [N m]."""
        tau = self.generalised_torque(q, loads)
        out = np.zeros(self.n_motors)
        for side in SIDES:
            leg = self.kinematics.legs[side]
            for k, motor in enumerate(leg.motors):
                out[motor] = tau[leg.v[k]]
            out[leg.motors[LegIndices.KNEE]] -= tau[leg.v[LegIndices.TARSUS]]
        return out
