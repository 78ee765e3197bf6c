"""What the state estimator reports each tick: :class:`EstimatedState` and :class:`BoardEstimate`.

Frames: ``W`` is the world (z up), ``B`` the robot's base body. Quaternions are
(w, x, y, z), base to world, as in MuJoCo and :class:`~ridempc.sim.sensors.ImuReading`.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ridempc.rotations import quaternion_to_matrix, yaw_of

__all__ = ["BoardEstimate", "EstimatedState", "JointValues"]

Array = NDArray[np.float64]


class JointValues(Mapping[str, float]):
    """Joint values by name, read from an array when asked.

    The estimator reports every joint by name at 500 Hz, and its readers look a few up at
    the MPC's 30 Hz: a dict of them each tick cost more than the lookups.

    Args:
        index: Position in ``values`` of each joint, in the map's order.
        values: The values [rad or rad/s]; kept, not copied.
    """

    __slots__ = ("_index", "_values")

    def __init__(self, index: Mapping[str, int], values: Array) -> None:
        self._index = index
        self._values = values

    def __getitem__(self, name: str) -> float:
        return float(self._values[self._index[name]])

    def __iter__(self) -> Iterator[str]:
        return iter(self._index)

    def __len__(self) -> int:
        return len(self._index)

    def __repr__(self) -> str:
        return f"JointValues({dict(self)!r})"


@dataclass(frozen=True)
class BoardEstimate:
    """A board's platform state seen through the rider's feet standing on it.

    The platform frame sits where the stance feet touch: its origin is the centroid of
    their contact points (or, with only some of the platform's feet down, where all of
    them would put it), its z axis the normal of the plane through them and its x axis the
    rider's forward direction projected on that plane (or a lone foot's toe line); see
    :func:`~ridempc.estimation.board.estimate_board`.

    Attributes:
        feet: The feet the estimate is taken from.
        position: Platform origin in the world [m].
        yaw: Heading of the platform's x axis [rad].
        pitch: Rotation about the platform's y axis (nose down positive) [rad].
        roll: Rotation about the platform's x axis (left side up positive) [rad].
        velocity: Mean world velocity of the stance feet [m/s].
        yaw_rate: Rate of yaw from the feet's relative velocity [rad/s] (0 with one foot).
    """

    feet: tuple[str, ...]
    position: Array
    yaw: float
    pitch: float
    roll: float
    velocity: Array
    yaw_rate: float


@dataclass(frozen=True)
class EstimatedState:
    """The estimator's view of the robot at one control tick.

    Attributes:
        time: Time of the sensor packet it was computed from [s].
        base_position: Base origin in the world [m].
        base_quaternion: Base orientation (w, x, y, z), base to world.
        base_velocity: Base origin's linear velocity in the world frame [m/s].
        base_angular_velocity: Base angular velocity in the base frame [rad/s].
        joint_position: Angle of every one-DoF joint by name [rad]: the encoders' readings,
            and for a closed chain the unmeasured joints solved from its loop closure.
        joint_velocity: Rate of every one-DoF joint by name [rad/s].
        q: Full Pinocchio configuration (base quaternion x, y, z, w; ball joints included)
            [m, -, rad].
        v: Full Pinocchio velocity (base linear and angular in the base frame) [m/s, rad/s].
        foot_names: The robot's foot bodies.
        contact: Whether each foot is judged in contact, ``foot_names`` order.
        foot_position: World position of each foot's point (the mean of its contact sites)
            [m], shape (feet, 3), from the filter.
        foot_velocity: World velocity of each foot's point [m/s], shape (feet, 3), from the
            legs and the estimated base velocity.
        boards: One estimate per board platform the estimator was told feet stand on
            (empty on the ground).
    """

    time: float
    base_position: Array
    base_quaternion: Array
    base_velocity: Array
    base_angular_velocity: Array
    joint_position: Mapping[str, float]
    joint_velocity: Mapping[str, float]
    q: Array
    v: Array
    foot_names: tuple[str, ...]
    contact: NDArray[np.bool_]
    foot_position: Array
    foot_velocity: Array
    boards: tuple[BoardEstimate, ...] = ()

    @property
    def board(self) -> BoardEstimate | None:
        """The first platform's estimate, or None on the ground."""
        return self.boards[0] if self.boards else None

    @property
    def yaw(self) -> float:
        """Heading of the base's x axis [rad]."""
        return yaw_of(self.base_quaternion)

    @property
    def rotation(self) -> Array:
        """:math:`R_{WB}` [3 x 3]."""
        return quaternion_to_matrix(self.base_quaternion)

    @property
    def yaw_rate(self) -> float:
        """The base's yaw rate, world z of the estimated angular velocity [rad/s]."""
        return float((self.rotation @ self.base_angular_velocity)[2])
