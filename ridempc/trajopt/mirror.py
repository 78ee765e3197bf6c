"""The mirror image of a trajectory of a left-right symmetric robot: :math:`y \\to -y`.

A quadruped is left-right symmetric, so a trajectory reflected in its sagittal plane is one it
can ride as well: the same push made with the other rear foot. With
:math:`M = \\mathrm{diag}(1, -1, 1)` the reflection,

.. math::

    p \\to M p, \\quad v \\to M v, \\quad f_i \\to M f_{\\sigma(i)}, \\quad
    \\omega \\to -M \\omega, \\quad \\theta_{roll} \\to -\\theta_{roll}, \\;
    \\theta_{pitch} \\to \\theta_{pitch}, \\; \\theta_{yaw} \\to -\\theta_{yaw}, \\quad
    q_j \\to s_j\\, q_{\\tau(j)}

(angular velocities are pseudovectors: :math:`\\det M = -1`), where :math:`\\sigma` pairs
each foot with its mirror foot and :math:`\\tau` each joint with its mirror joint, with the sign
:math:`s_j` that makes the mirror joint move its foot as the reflected joint does (kept for
hip and knee pitch, flipped for ab/adduction on the usual legs). All three are read
from the robot's kinematics, never from its names (:func:`robot_symmetry`): feet pair by
their places at the riding stance, joints by their order along the two legs, signs by the
feet's Jacobians. A board of one platform mirrors by its states' canonical quantities
(:mod:`ridempc.boards.canonical`): its lateral place, heading, yaw rate, roll and roll rate
change sign.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.canonical import BoardState
from ridempc.errors import ConfigError
from ridempc.trajopt.rigid_body import RigidBodyRobot, rigid_body_state_names
from ridempc.trajopt.schedule import Contact

__all__ = ["Mirror", "Symmetry", "robot_symmetry", "symmetry_or_none"]

Array = NDArray[np.float64]
# [m] how far a foot's reflected place at the riding stance may be from its mirror foot's:
# a model's rounding (a trunk whose CoM sits 0.2 mm off its sagittal plane), not a
# different leg
SYMMETRY_TOLERANCE: float = 2e-3
# Sign of each rigid-body state of eq. (1) under the reflection, in
# rigid_body_state_names' order: CoM (x, y, z), Z-Y-X angles (roll, pitch, yaw), CoM
# velocity, body angular rate (a pseudovector: -M w)
_RIGID_BODY_SIGNS: tuple[float, ...] = (1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1)
# Sign of each canonical board quantity under the reflection (ridempc.boards.canonical)
_BOARD_SIGNS: dict[str, float] = {
    "x": 1.0,
    "y": -1.0,
    "heading": -1.0,
    "speed": 1.0,
    "pitch": 1.0,
    "pitch_rate": 1.0,
    "yaw_rate": -1.0,
    "roll": -1.0,
    "roll_rate": -1.0,
}
_FORCE_SIGNS: dict[str, float] = {"x": 1.0, "y": -1.0, "z": 1.0}
_REFLECT = np.diag([1.0, -1.0, 1.0])


@dataclass(frozen=True)
class Symmetry:
    """A robot's left-right symmetry.

    Attributes:
        base: The base body, whose angles the states carry.
        feet: Contact sites, in the robot's foot order.
        foot_mirror: Per foot, the index of its mirror foot.
        side: Per foot, +1 left of the sagittal plane, -1 right (its place at the stance).
        joints: Joint names, the order of :math:`q_j`.
        joint_mirror: Per joint, the index of its mirror joint.
        joint_sign: Per joint, :math:`s_j` (+1 or -1).
        com_offset: The centre of mass's distance left of the trunk's sagittal plane,
            :math:`c_y` [m] (the states carry the centre of mass, the kinematics the trunk).
    """

    base: str
    feet: tuple[str, ...]
    foot_mirror: tuple[int, ...]
    side: tuple[float, ...]
    joints: tuple[str, ...]
    joint_mirror: tuple[int, ...]
    joint_sign: tuple[float, ...]
    com_offset: float = 0.0


def _column(robot: RigidBodyRobot, q: Array, foot: int, joint: int) -> Array:
    """The trunk-frame velocity of ``foot`` [m/s] per rad/s of ``joint``, at ``q``."""
    symbol = ca.SX.sym("q", robot.n_joints)
    value = ca.Function("column", [symbol], [robot.foot_jacobian(symbol, foot)[:, joint]])
    return np.asarray(value(q), dtype=float).ravel()


def _feet(robot: RigidBodyRobot, q: Array) -> Array:
    """The feet's places in the trunk frame at ``q`` [m], n_feet x 3."""
    return np.array([np.asarray(p, dtype=float).ravel() for p in robot.feet_in_trunk(q)])


def robot_symmetry(robot: RigidBodyRobot) -> Symmetry:
    """The robot's left-right symmetry, read from its kinematics at its riding stance.

    Raises:
        ConfigError: The robot is not left-right symmetric (a foot without a mirror foot, a
            leg of another length, or a mirrored stance whose feet are not the stance's
            reflected).
    """
    q = robot.q_reference
    places = _feet(robot, q)
    reflected = places @ _REFLECT
    feet: list[int] = []
    for i, place in enumerate(reflected):
        distance = np.linalg.norm(places - place, axis=1)
        j = int(np.argmin(distance))
        if distance[j] > SYMMETRY_TOLERANCE or len(robot.legs[i]) != len(robot.legs[j]):
            raise ConfigError(
                f"robot '{robot.name}' is not left-right symmetric: foot '{robot.feet[i]}' "
                f"reflected is {distance[j]:.4f} m from the nearest foot '{robot.feet[j]}' "
                f"(allowed: {SYMMETRY_TOLERANCE} m)"
            )
        feet.append(j)
    joint_mirror = list(range(robot.n_joints))
    joint_sign = [1.0] * robot.n_joints
    for i, j in enumerate(feet):
        for a, b in zip(robot.legs[i], robot.legs[j], strict=True):
            joint_mirror[a] = b
            moved = _REFLECT @ _column(robot, q, i, a)
            other = _column(robot, q, j, b)
            joint_sign[a] = 1.0 if float(moved @ other) >= 0.0 else -1.0
    mirrored_q = np.array([joint_sign[k] * q[joint_mirror[k]] for k in range(robot.n_joints)])
    gap = float(np.max(np.abs(_feet(robot, mirrored_q) - reflected[feet])))
    if gap > SYMMETRY_TOLERANCE:
        raise ConfigError(
            f"robot '{robot.name}' is not left-right symmetric: its mirrored stance puts a "
            f"foot {gap:.4f} m from the reflected stance's (allowed: {SYMMETRY_TOLERANCE} m)"
        )
    side = tuple(1.0 if y >= 0.0 else -1.0 for y in places[:, 1])
    return Symmetry(
        robot.base,
        tuple(robot.feet),
        tuple(feet),
        side,
        tuple(robot.joints),
        tuple(joint_mirror),
        tuple(joint_sign),
        float(robot.com_in_trunk[1]),
    )


def symmetry_or_none(robot: RigidBodyRobot) -> Symmetry | None:
    """:func:`robot_symmetry`, or None for a robot that is not left-right symmetric."""
    try:
        return robot_symmetry(robot)
    except ConfigError:
        return None


@dataclass(frozen=True)
class Mirror:
    """The reflection of one pair's state and input vectors (an involution).

    Attributes:
        state_source: Per state, the index of the state it takes its value from.
        state_sign: Per state, the sign it takes it with.
        input_source: Per input, likewise.
        input_sign: Per input, likewise.
        contact_source: Per contact (the feet's order), its mirror contact.
        com: Indices of the centre of mass's x, y, z and of the base's roll, pitch, yaw.
        com_shift: :math:`2 c_y` [m]: the reflected trunk carries its centre of mass this
            far to its left of the reflected centre of mass.
    """

    state_source: tuple[int, ...]
    state_sign: Array
    input_source: tuple[int, ...]
    input_sign: Array
    contact_source: tuple[int, ...]
    com: tuple[int, ...] = ()
    com_shift: float = 0.0

    @classmethod
    def of(
        cls,
        symmetry: Symmetry,
        state_names: Sequence[str],
        input_names: Sequence[str],
        board_states: Mapping[str, BoardState],
    ) -> Mirror:
        """The mirror of a pair's vectors, named as the SRBKM libraries name them: the rigid
        body's states (:func:`rigid_body_state_names`), ``q_<joint>``, the board's states
        (one platform), ``f_<foot>_<axis>`` and ``qd_<joint>``.

        Raises:
            ConfigError: A name that is none of these, or a board of several platforms
                (whose mirror swaps platforms, not signs).
        """
        table: dict[str, tuple[str, float]] = {}
        for name, sign in zip(
            rigid_body_state_names(symmetry.base), _RIGID_BODY_SIGNS, strict=True
        ):
            table[name] = (name, sign)
        for k, joint in enumerate(symmetry.joints):
            other, sign = symmetry.joints[symmetry.joint_mirror[k]], symmetry.joint_sign[k]
            table[f"q_{joint}"] = (f"q_{other}", sign)
            table[f"qd_{joint}"] = (f"qd_{other}", sign)
        for k, foot in enumerate(symmetry.feet):
            other = symmetry.feet[symmetry.foot_mirror[k]]
            for axis, sign in _FORCE_SIGNS.items():
                table[f"f_{foot}_{axis}"] = (f"f_{other}_{axis}", sign)
        for name, state in board_states.items():
            if state.platform != 0:
                raise ConfigError(
                    f"board state '{name}' is of platform {state.platform}: only a board of "
                    "one platform mirrors by its states' signs"
                )
            table[name] = (name, _BOARD_SIGNS[state.quantity])

        def mapped(names: Sequence[str]) -> tuple[tuple[int, ...], Array]:
            index = {n: i for i, n in enumerate(names)}
            sources, signs = [], []
            for name in names:
                if name not in table or table[name][0] not in index:
                    raise ConfigError(f"cannot mirror '{name}': no mirror among {list(names)}")
                other, sign = table[name]
                sources.append(index[other])
                signs.append(sign)
            return tuple(sources), np.array(signs, dtype=float)

        states, state_sign = mapped(state_names)
        inputs, input_sign = mapped(input_names)
        index = {n: i for i, n in enumerate(state_names)}
        body = rigid_body_state_names(symmetry.base)
        com = tuple(index[n] for n in body[:6])
        return cls(
            states,
            state_sign,
            inputs,
            input_sign,
            symmetry.foot_mirror,
            com,
            2.0 * symmetry.com_offset,
        )

    def rates(self, values: Array) -> Array:
        """State rates or offsets (..., nx) reflected."""
        return np.asarray(values, dtype=float)[..., list(self.state_source)] * self.state_sign

    def states(self, values: Array) -> Array:
        """States (..., nx) reflected: :meth:`rates`, and the centre of mass moved by
        :math:`R (0, 2 c_y, 0)` (:math:`R` the reflected base's rotation, Z-Y-X), so that
        every foot lands on the reflection of its mirror foot's place and the deck's rows
        obey the mirrored dynamics. A robot whose CoM is off its plane is not exactly its
        own mirror: its trunk's roll keeps a residual of :math:`2 c_y m g` (0.02 N m, 0.25
        rad/s^2 for a CoM 0.12 mm off the plane of a 9 kg robot), left to the MPC's
        feedback."""
        mirrored = self.rates(values)
        if self.com_shift == 0.0:
            return mirrored
        roll, pitch, yaw = (mirrored[..., i] for i in self.com[3:])
        cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
        cy, sy = np.cos(yaw), np.sin(yaw)
        lateral = (cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr)  # R e_y
        for i, axis in zip(self.com[:3], lateral, strict=True):
            mirrored[..., i] += self.com_shift * axis
        return mirrored

    def inputs(self, values: Array) -> Array:
        """Inputs (..., nu) reflected."""
        return np.asarray(values, dtype=float)[..., list(self.input_source)] * self.input_sign

    def contacts(self, places: Sequence[Contact]) -> tuple[Contact, ...]:
        """Per contact, where its mirror contact is."""
        return tuple(places[j] for j in self.contact_source)

    def per_contact(self, values: Array) -> Array:
        """Per-contact columns (..., n_c) (the skate pair's deck mask) exchanged."""
        return np.asarray(values, dtype=float)[..., list(self.contact_source)]
