"""Encoder readings into Pinocchio coordinates: which joints are measured, which are not.

The sensor packet lists encoder positions and velocities in ``robot.encoder_joints``
order (the motor joints, then the instrumented passive joints). :class:`JointMap` writes
them into a Pinocchio configuration :math:`q` and velocity :math:`v` with the base at the
world origin and the estimated orientation:

.. math::

    q = (0, 0, 0,\\ \\mathrm{quat}_{xyzw}(R_{WB}),\\ q_J), \\qquad
    v = (0, 0, 0,\\ \\omega_B,\\ \\dot q_J),

so that frame positions from Pinocchio are positions relative to the base origin,
expressed in the world's axes [m]. Joints without an encoder (the achilles rod and heel
spring of a closed chain) keep the values given to :meth:`JointMap.write`, for
:class:`~ridempc.estimation.loop_closure.LoopClosure` to solve.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError

__all__ = ["JointMap"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]


@dataclass(frozen=True)
class JointMap:
    """Where each encoder's reading goes in Pinocchio's :math:`q` and :math:`v`.

    Attributes:
        encoder_q: q index of each encoder joint, packet order.
        encoder_v: v index of each encoder joint, packet order.
        unmeasured_v: v indices of joints without an encoder (root excluded).
        hinge_names: Names of every one-DoF joint (hinge or slide), model order.
        hinge_q: Their q indices.
        hinge_v: Their v indices.
    """

    encoder_q: Index
    encoder_v: Index
    unmeasured_v: Index
    hinge_names: tuple[str, ...]
    hinge_q: Index
    hinge_v: Index

    @classmethod
    def build(cls, model: pin.Model, encoder_joints: Sequence[str]) -> JointMap:
        """Index the encoders of ``model`` (a floating-base tree, root joint first).

        Raises:
            ConfigError: An encoder joint is missing from the model or is not one-DoF.
        """
        encoder_q, encoder_v = [], []
        for name in encoder_joints:
            if not model.existJointName(name):
                raise ConfigError(f"encoder joint '{name}' is not a joint of '{model.name}'")
            joint = model.joints[model.getJointId(name)]
            if joint.nq != 1 or joint.nv != 1:
                raise ConfigError(f"encoder joint '{name}' has {joint.nv} DoF, expected 1")
            encoder_q.append(joint.idx_q)
            encoder_v.append(joint.idx_v)
        measured = set(encoder_v)
        unmeasured = [
            i for j in model.joints[2:] for i in range(j.idx_v, j.idx_v + j.nv) if i not in measured
        ]
        hinges = [(n, j) for n, j in zip(model.names[2:], model.joints[2:], strict=True)]
        hinges = [(n, j) for n, j in hinges if j.nq == 1 and j.nv == 1]
        return cls(
            encoder_q=np.array(encoder_q, dtype=np.int64),
            encoder_v=np.array(encoder_v, dtype=np.int64),
            unmeasured_v=np.array(unmeasured, dtype=np.int64),
            hinge_names=tuple(n for n, _ in hinges),
            hinge_q=np.array([j.idx_q for _, j in hinges], dtype=np.int64),
            hinge_v=np.array([j.idx_v for _, j in hinges], dtype=np.int64),
        )

    def write(
        self,
        q: Array,
        v: Array,
        base_quaternion: Array,
        base_angular_velocity: Array,
        encoder_position: Array,
        encoder_velocity: Array,
    ) -> None:
        """Fill ``q`` and ``v`` in place: base at the origin, encoders at their readings.

        Args:
            q: Pinocchio configuration, overwritten except at unmeasured joints.
            v: Pinocchio velocity, overwritten except at unmeasured joints.
            base_quaternion: :math:`R_{WB}` as (w, x, y, z).
            base_angular_velocity: :math:`\\omega_B` [rad/s].
            encoder_position: Encoder angles [rad], packet order.
            encoder_velocity: Encoder rates [rad/s], packet order.
        """
        q[:3] = 0.0
        q[3:6] = base_quaternion[1:]  # Pinocchio's (x, y, z, w)
        q[6] = base_quaternion[0]
        q[self.encoder_q] = encoder_position
        v[:3] = 0.0
        v[3:6] = base_angular_velocity
        v[self.encoder_v] = encoder_velocity
