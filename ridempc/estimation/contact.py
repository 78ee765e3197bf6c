"""Contact detection from what the robot senses: spring deflection or joint torques.

A foot's *load* :math:`\\ell_i` is the part of the robot's weight it carries, as a fraction
of its standing share, from one of two signals:

- ``spring`` (legs with a measured leaf spring, Cassie's shin): the spring's deflection
  against its deflection in the standing keyframe,
  :math:`\\ell_i = (q_s - q_{s,0}) / (q_{s,stand} - q_{s,0})`;
- ``torque`` (fully actuated legs): the static contact force from the motor torques and
  gravity, :math:`J_{i,leg}^\\top f_i = g_{leg}(q) - \\tau_{leg}` (world-aligned
  :math:`J`, leg inertia neglected), :math:`\\ell_i = f_{i,z} / (m g / n_{feet})`.

A Schmitt trigger turns the load into a contact flag: a foot enters contact above
``contact_on`` and leaves below ``contact_off``. Signals are chosen by name from
:data:`CONTACT_LOADS`; ``auto`` takes springs when every foot's chain has one with an
encoder, torques otherwise.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.estimation.lapack import solve
from ridempc.estimation.legs import LegKinematics, LegReading
from ridempc.estimation.parameters import EstimatorParameters
from ridempc.gravity import GRAVITY as STANDARD_GRAVITY
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.robots.robot import Robot

__all__ = [
    "CONTACT_LOADS",
    "ContactDetector",
    "FootLoad",
    "SpringLoad",
    "TorqueLoad",
    "build_contact_detector",
]

Array = NDArray[np.float64]
Index = NDArray[np.int64]


class FootLoad(ABC):
    """A load signal per foot, as a fraction of its standing share [-]."""

    @abstractmethod
    def loads(
        self,
        model: pin.Model,
        data: pin.Data,
        q: Array,
        encoder_position: Array,
        motor_torque: Array,
        legs: LegReading,
    ) -> Array:
        """:math:`\\ell_i` per foot [-]."""


@dataclass(frozen=True)
class SpringLoad(FootLoad):
    """Load from the deflection of a measured spring on each foot's chain.

    Attributes:
        encoder: Encoder (packet) index of each foot's spring.
        rest: Spring rest angle :math:`q_{s,0}` [rad] per foot.
        standing: Spring angle in the standing keyframe :math:`q_{s,stand}` [rad] per foot.
    """

    encoder: Index
    rest: Array
    standing: Array

    @classmethod
    def build(cls, robot: Robot, pinocchio: PinocchioRobot, legs: LegKinematics) -> SpringLoad:
        """The first measured spring on each foot's chain.

        Raises:
            ConfigError: A foot has no measured spring, or it is not loaded when standing.
        """
        encoder_v = _encoder_v(robot, pinocchio)
        stand_q = pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
        model = pinocchio.model
        encoders, rests, standings = [], [], []
        for foot in legs.feet:
            springs = [i for i in foot.chain_v if pinocchio.spring_stiffness[i] > 0]
            measured = [i for i in springs if i in encoder_v]
            if not measured:
                raise ConfigError(
                    f"contact 'spring': foot '{foot.name}' of '{robot.name}' has no spring "
                    "with an encoder on its chain"
                )
            v_index = measured[0]
            joint = next(j for j in range(2, model.njoints) if model.idx_vs[j] == v_index)
            rest = float(pinocchio.spring_reference[v_index])
            standing = float(stand_q[model.idx_qs[joint]])
            if abs(standing - rest) < 1e-4:
                raise ConfigError(
                    f"contact 'spring': spring '{model.names[joint]}' is not deflected in the "
                    "standing keyframe, so its standing load is unknown"
                )
            encoders.append(encoder_v.index(v_index))
            rests.append(rest)
            standings.append(standing)
        return cls(np.array(encoders), np.array(rests), np.array(standings))

    def loads(self, model, data, q, encoder_position, motor_torque, legs) -> Array:
        return (encoder_position[self.encoder] - self.rest) / (self.standing - self.rest)


@dataclass(frozen=True)
class TorqueLoad(FootLoad):
    """Load from the static contact force the motor torques balance.

    Attributes:
        joints: v indices of the joints on the feet's chains.
        motor_of_joint: Motor (actuator) index of each of ``joints``.
        on_chain: 1 where a row of a foot's Jacobian meets a joint of its own chain, else 0,
            shape (3 feet, joints): a foot's force loads only its own leg.
        share: Standing share of each foot :math:`m g / n_{feet}` [N].
    """

    joints: Index
    motor_of_joint: Index
    on_chain: Array
    share: float

    @classmethod
    def build(cls, robot: Robot, pinocchio: PinocchioRobot, legs: LegKinematics) -> TorqueLoad:
        """Raises ConfigError if a foot's chain has a joint without a motor."""
        model = pinocchio.model
        motor_v = [int(model.joints[model.getJointId(m.joint)].idx_v) for m in robot.motors]
        for foot in legs.feet:
            unactuated = [int(i) for i in foot.chain_v if int(i) not in motor_v]
            if unactuated:
                raise ConfigError(
                    f"contact 'torque': foot '{foot.name}' of '{robot.name}' has passive "
                    f"joints on its chain (v indices {unactuated}); use 'spring'"
                )
        share = robot.mass * STANDARD_GRAVITY / len(legs.feet)
        joints = np.unique(np.concatenate([f.chain_v for f in legs.feet]))
        on_chain = np.zeros((3 * len(legs.feet), joints.size))
        for i, foot in enumerate(legs.feet):
            on_chain[3 * i : 3 * i + 3, np.isin(joints, foot.chain_v)] = 1.0
        motor_of_joint = np.array([motor_v.index(int(j)) for j in joints])
        return cls(joints, motor_of_joint, on_chain, share)

    def loads(self, model, data, q, encoder_position, motor_torque, legs) -> Array:
        residual = pin.computeGeneralizedGravity(model, data, q)[self.joints]
        residual -= motor_torque[self.motor_of_joint]
        # J^T f = g - tau for all feet at once; least squares f = (J J^T)^-1 J (g - tau)
        jacobian = legs.foot_jacobian[:, :, self.joints].reshape(-1, self.joints.size)
        jacobian = jacobian * self.on_chain
        gram = jacobian @ jacobian.T + self._ridge
        force = solve(gram, jacobian @ residual).reshape(-1, 3)
        return force[:, 2] / self.share

    @cached_property
    def _ridge(self) -> Array:
        """:math:`10^{-9} I` [m^2], keeping the Gram matrix of a singular leg invertible."""
        return 1e-9 * np.eye(self.on_chain.shape[0])


CONTACT_LOADS: dict[str, Callable[[Robot, PinocchioRobot, LegKinematics], FootLoad]] = {
    "spring": SpringLoad.build,
    "torque": TorqueLoad.build,
}


def _encoder_v(robot: Robot, pinocchio: PinocchioRobot) -> list[int]:
    model = pinocchio.model
    return [int(model.joints[model.getJointId(j)].idx_v) for j in robot.encoder_joints]


@dataclass
class ContactDetector:
    """A load signal and the Schmitt trigger on it.

    Attributes:
        load: The load signal.
        on: Load fraction to enter contact [-].
        off: Load fraction to leave contact [-].
        contact: Current flag per foot.
        last_load: Last load per foot [-].
    """

    load: FootLoad
    on: float
    off: float
    contact: NDArray[np.bool_]
    last_load: Array

    def update(
        self,
        model: pin.Model,
        data: pin.Data,
        q: Array,
        encoder_position: Array,
        motor_torque: Array,
        legs: LegReading,
    ) -> NDArray[np.bool_]:
        """The contact flags at this tick."""
        load = self.load.loads(model, data, q, encoder_position, motor_torque, legs)
        self.last_load = load
        self.contact = np.where(self.contact, load > self.off, load > self.on)
        return self.contact.copy()


def build_contact_detector(
    robot: Robot, pinocchio: PinocchioRobot, legs: LegKinematics, params: EstimatorParameters
) -> ContactDetector:
    """The detector ``params.contact_method`` names (``auto``: springs if every foot has one).

    Raises:
        UnknownNameError: No such load signal.
        ConfigError: The signal does not apply to this robot.
    """
    method = params.contact_method
    if method == "auto":
        encoder_v = set(_encoder_v(robot, pinocchio))
        sprung = all(
            any(pinocchio.spring_stiffness[i] > 0 and int(i) in encoder_v for i in foot.chain_v)
            for foot in legs.feet
        )
        method = "spring" if sprung else "torque"
    if method not in CONTACT_LOADS:
        raise UnknownNameError("contact load signal", method, CONTACT_LOADS)
    n = len(legs.feet)
    return ContactDetector(
        load=CONTACT_LOADS[method](robot, pinocchio, legs),
        on=params.contact_on,
        off=params.contact_off,
        contact=np.ones(n, dtype=bool),
        last_load=np.ones(n),
    )
