"""What the whole-body controller is asked for (:class:`WbcTargets`) and what it returns
(:class:`WbcOutput`).

Frames: everything is in the world frame W (z up) unless said otherwise; quaternions are
(w, x, y, z), base to world, as in :class:`~ridempc.estimation.EstimatedState`. Per-foot
arrays follow the robot's ``foot_bodies`` order (``EstimatedState.foot_names``); per-motor
arrays follow the actuator order (``Robot.motors``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ridempc.errors import ConfigError

__all__ = ["WbcOutput", "WbcTargets"]

Array = NDArray[np.float64]
_VECTORS: tuple[str, ...] = (  # the targets' 3-vectors, made float arrays
    "position",
    "velocity",
    "acceleration",
    "angular_velocity",
    "angular_acceleration",
)


def _zeros3() -> Array:
    return np.zeros(3)


def _check_shape(name: str, value: object, shape: tuple[int, ...]) -> None:
    array = value if isinstance(value, np.ndarray) else np.asarray(value)
    if array.shape != shape or not np.isfinite(array).all():
        raise ConfigError(
            f"WBC targets: field '{name}': expected finite values of shape {shape}, "
            f"got shape {array.shape}"
        )


@dataclass(frozen=True)
class WbcTargets:
    """The MPC's references for one 500 Hz tick.

    Attributes:
        position: Centre of mass (or base origin, as the controller is built) [m].
        orientation: Base orientation, unit quaternion (w, x, y, z) (normalised here).
        contact: Planned contact of each foot (True: it stands and may push).
        forces: The support's force on each foot [N], shape (feet, 3); ignored for feet in
            the air.
        velocity: Velocity of ``position`` [m/s].
        acceleration: Feedforward acceleration of ``position`` [m/s^2].
        angular_velocity: Base angular velocity [rad/s] (world axes).
        angular_acceleration: Feedforward base angular acceleration [rad/s^2] (world axes).
        swing_position: Target of each foot's point (the mean of its contact sites) [m],
            shape (feet, 3), used for the feet not in contact (push-off); None: no swing task.
        swing_velocity: Its velocity [m/s] (zero if None).
        swing_acceleration: Its feedforward acceleration [m/s^2] (zero if None).
        posture: Nominal motor joint angles [rad], actuator order; None: the controller's.
        board_acceleration: Per board estimate in ``EstimatedState.boards``, the platform
            origin's acceleration [m/s^2]; empty or missing entries mean zero.
        site_forces: The support's force on each contact site [N], shape (sites, 3), in
            ``robot.params.contact_sites`` order, or None. When given, each standing site's
            force is drawn to it, so the MPC's centre of pressure along a line foot (what
            pitches a hovershoe) is the one applied; when None, a foot's force is shared
            evenly between its sites and the motion tasks choose the centre of pressure.
    """

    position: Array
    orientation: Array
    contact: NDArray[np.bool_]
    forces: Array
    velocity: Array = field(default_factory=_zeros3)
    acceleration: Array = field(default_factory=_zeros3)
    angular_velocity: Array = field(default_factory=_zeros3)
    angular_acceleration: Array = field(default_factory=_zeros3)
    swing_position: Array | None = None
    swing_velocity: Array | None = None
    swing_acceleration: Array | None = None
    posture: Array | None = None
    board_acceleration: tuple[Array, ...] = ()
    site_forces: Array | None = None

    def __post_init__(self) -> None:
        for name in _VECTORS:
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float))
        orientation = np.asarray(self.orientation, dtype=float)
        if self.site_forces is not None:
            object.__setattr__(self, "site_forces", np.asarray(self.site_forces, dtype=float))
        if not self._shapes_fit():
            self._check_each()  # raises, naming the field
        norm = math.sqrt(orientation.dot(orientation))  # np.linalg.norm's sum
        if abs(norm - 1.0) > 1e-3:
            raise ConfigError(
                f"WBC targets: field 'orientation': not a unit quaternion (norm {norm:.6f})"
            )
        object.__setattr__(self, "orientation", orientation / norm)

    def _shapes_fit(self) -> bool:
        """Whether every field has its shape and finite values, checked at once (a tick's
        dozen small checks one by one cost more than the rest of the targets)."""
        feet = len(self.contact)
        arrays = [getattr(self, name) for name in _VECTORS]
        shapes: list[tuple[int, ...]] = [(3,)] * len(arrays)
        arrays.append(np.asarray(self.orientation))
        shapes.append((4,))
        for name in ("forces", "swing_position", "swing_velocity", "swing_acceleration"):
            value = getattr(self, name)
            if value is not None:
                arrays.append(np.asarray(value))
                shapes.append((feet, 3))
        if self.site_forces is not None:
            arrays.append(self.site_forces)
            shapes.append((len(self.site_forces), 3))
        for acceleration in self.board_acceleration:
            arrays.append(np.asarray(acceleration))
            shapes.append((3,))
        if any(a.shape != shape for a, shape in zip(arrays, shapes, strict=True)):
            return False
        if any(a.dtype.kind not in "fiu" for a in arrays):
            return False
        return bool(np.isfinite(np.concatenate([a.ravel() for a in arrays])).all())

    def _check_each(self) -> None:
        """Each field's shape and values, one by one.

        Raises:
            ConfigError: The first field of the wrong shape or with a value not finite.
        """
        for name in _VECTORS:
            _check_shape(name, getattr(self, name), (3,))
        _check_shape("orientation", self.orientation, (4,))
        feet = len(np.asarray(self.contact))
        _check_shape("forces", self.forces, (feet, 3))
        for name in ("swing_position", "swing_velocity", "swing_acceleration"):
            value = getattr(self, name)
            if value is not None:
                _check_shape(name, value, (feet, 3))
        if self.site_forces is not None:
            _check_shape("site_forces", self.site_forces, (len(self.site_forces), 3))
        for k, acceleration in enumerate(self.board_acceleration):
            _check_shape(f"board_acceleration[{k}]", acceleration, (3,))

    @property
    def n_feet(self) -> int:
        return len(np.asarray(self.contact))


@dataclass(frozen=True)
class WbcOutput:
    """The whole-body QP's answer for one tick.

    The joint targets integrate the solution's acceleration over one tick :math:`\\Delta t`:
    :math:`q^* = q + v \\Delta t + \\tfrac12 \\ddot q \\Delta t^2`,
    :math:`\\dot q^* = v + \\ddot q \\Delta t`, for the low-level PD
    :math:`\\tau_{motor} = \\tau + k_p (q^* - q) + k_d (\\dot q^* - \\dot q)`.

    Attributes:
        torque: Motor torques [N m], actuator order (joint side).
        position: Motor joint position targets :math:`q^*` [rad].
        velocity: Motor joint velocity targets :math:`\\dot q^*` [rad/s].
        acceleration: The solution's :math:`\\ddot q` (Pinocchio coordinates).
        forces: The support's force on each foot [N], shape (feet, 3).
        site_forces: On each contact site [N], shape (sites, 3).
        site_positions: Where each contact site is at the estimated state [m], world, shape
            (sites, 3).
        com_velocity: The centre of mass's velocity at the estimated state [m/s], world.
        loop_forces: Closed-chain constraint forces :math:`\\lambda` [N].
        status: OSQP's status (``solved`` or ``solved inaccurate``).
        iterations: ADMM iterations.
        model_ms: Pinocchio model update [ms].
        build_ms: Building the QP's matrices (tasks and constraints) [ms].
        solve_ms: OSQP update, factorisation and solve [ms].
    """

    torque: Array
    position: Array
    velocity: Array
    acceleration: Array
    forces: Array
    site_forces: Array
    site_positions: Array
    com_velocity: Array
    loop_forces: Array
    status: str
    iterations: int
    model_ms: float
    build_ms: float
    solve_ms: float

    @property
    def total_ms(self) -> float:
        """Model update, QP build and QP solve [ms]."""
        return self.model_ms + self.build_ms + self.solve_ms
