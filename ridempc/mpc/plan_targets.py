"""What the plan asks of the whole-body controller at a 500 Hz tick, in the world.

Between two MPC solves each tick follows the plan's first step, interpolated
:math:`x(s) = (1 - s)\\,x_0 + s\\,x_1` a share :math:`s` of the way through it
(:meth:`~ridempc.mpc.plan.Plan.first_step_state`), and turned from the library frame it was
solved in into the world by that frame's yaw :math:`\\Delta\\psi` and offset
(:class:`~ridempc.mpc.state_map.PlanarFrame`):

- the centre of mass :math:`c^*` [m] and its velocity [m/s];
- the base orientation :math:`R = R_z(\\psi + \\Delta\\psi) R_y(\\vartheta) R_x(\\phi)` from the
  plan's Z-Y-X angles (Pinocchio's ``rpyToMatrix``), as a (w, x, y, z) quaternion with
  :math:`w \\ge 0`, and the base angular velocity :math:`R\\,\\omega_B` [rad/s];
- where the pair feeds them forward (its pair file's ``wbc.feedforward``, a share), the
  first step's accelerations :math:`(v_1 - v_0)/\\Delta t` [m/s^2] and
  :math:`R (\\omega_1 - \\omega_0)/\\Delta t` [rad/s^2];
- the first input's contact forces [N], per library contact and summed per foot.

The state's rows are looked up once (:class:`PlanReader`), so that a tick costs a handful of
array operations rather than one per coordinate (products by ``.dot``: NumPy 2's ``@`` costs
some 2 us more a call on 3-vectors). What does not change through the step (the frame's turn,
the forces, the centre of mass's feedforward) is read once per plan and frame, on the first
tick that reads them (:class:`_Steady`), and handed out read-only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.mpc.plan import Plan
from ridempc.mpc.state_map import PlanarFrame

__all__ = ["PlanReader", "PlanTargets"]

Array = NDArray[np.float64]


class PlanTargets(NamedTuple):
    """One tick's targets from the plan, world axes.

    Attributes:
        position: Centre of mass [m].
        velocity: Its velocity [m/s].
        rotation: Base orientation :math:`R_{WB}`.
        orientation: The same as a unit quaternion (w, x, y, z), :math:`w \\ge 0`.
        angular_velocity: Base angular velocity [rad/s].
        acceleration: Feedforward centre of mass acceleration [m/s^2] (zero without).
        angular_acceleration: Feedforward base angular acceleration [rad/s^2] (zero without).
        forces: The support's force on each foot [N], shape (feet, 3).
        site_forces: On each library contact [N], shape (contacts, 3).
    """

    position: Array
    velocity: Array
    rotation: Array
    orientation: Array
    angular_velocity: Array
    acceleration: Array
    angular_acceleration: Array
    forces: Array
    site_forces: Array


class _Steady(NamedTuple):
    """A plan's targets that stay the same through its first step, in the world."""

    plan: Plan
    frame: PlanarFrame
    turn: Array
    acceleration: Array
    omega_step: Array | None
    forces: Array
    site_forces: Array


def _read_only(array: Array) -> Array:
    """``array``, its writes refused (it is handed out on every tick of its plan)."""
    array.flags.writeable = False
    return array


class PlanReader:
    """Reads a plan's first step as whole-body targets (module docstring).

    Args:
        names: Index of each state in the plan's state vector (``com_x`` ... ``wz`` and the
            base's ``roll``, ``pitch``, ``yaw`` under ``base_prefix``).
        base_prefix: The prefix of the base's angles.
        force_index: Per library contact, the input indices of its force (x, y, z).
        contact_foot: Per library contact, its foot.
        feet: How many feet.
        feedforward: Share of the first step's accelerations fed forward [-] (0: none).
        dt: The MPC's step [s].
    """

    def __init__(
        self,
        names: Mapping[str, int],
        base_prefix: str,
        force_index: NDArray[np.int64],
        contact_foot: Sequence[int],
        feet: int,
        feedforward: float,
        dt: float,
    ) -> None:
        def rows(*keys: str) -> NDArray[np.int64]:
            return np.array([names[k] for k in keys], dtype=np.int64)

        self._com = rows("com_x", "com_y", "com_z")
        self._velocity = rows("vx", "vy", "vz")
        self._omega = rows("wx", "wy", "wz")
        self._angles = tuple(names[f"{base_prefix}{a}"] for a in ("roll", "pitch", "yaw"))
        self._force_index = np.asarray(force_index, dtype=np.int64)
        # per foot, the sum of its contacts' forces
        self._to_feet = np.zeros((feet, len(contact_foot)))
        self._to_feet[list(contact_foot), np.arange(len(contact_foot))] = 1.0
        self.feedforward, self.dt = feedforward, dt
        self._steady: _Steady | None = None

    def _steady_of(self, plan: Plan, frame: PlanarFrame) -> _Steady:
        """The targets of ``plan`` in ``frame`` that do not change through its first step,
        computed on its first tick and kept until the plan or the frame changes."""
        steady = self._steady
        if steady is not None and steady.plan is plan and steady.frame is frame:
            return steady
        turn = frame.rotation()
        acceleration, omega_step = np.zeros(3), None
        if self.feedforward:
            first, second = plan.states[0], plan.states[1]
            scale = self.feedforward
            velocity_step = scale * (second[self._velocity] - first[self._velocity]) / self.dt
            omega_step = scale * (second[self._omega] - first[self._omega]) / self.dt
            acceleration = turn.dot(velocity_step)
        site_forces = plan.first_input[self._force_index].dot(turn.T)
        forces = self._to_feet.dot(site_forces)
        self._steady = steady = _Steady(
            plan,
            frame,
            _read_only(turn),
            _read_only(acceleration),
            omega_step,
            _read_only(forces),
            _read_only(site_forces),
        )
        return steady

    def __call__(self, plan: Plan, frame: PlanarFrame, share: float) -> PlanTargets:
        """The targets ``share`` [-] of the way through ``plan``'s first step, whose library
        frame is ``frame``."""
        steady = self._steady_of(plan, frame)
        x = plan.first_step_state(share)
        roll, pitch, yaw = (float(x[i]) for i in self._angles)
        rotation = np.asarray(pin.rpy.rpyToMatrix(roll, pitch, yaw + frame.yaw))
        qx, qy, qz, qw = pin.Quaternion(rotation).coeffs().tolist()
        orientation = np.array([qw, qx, qy, qz] if qw >= 0.0 else [-qw, -qx, -qy, -qz])
        omega_step = steady.omega_step
        return PlanTargets(
            position=frame.point_to_world(x[self._com]),
            velocity=steady.turn.dot(x[self._velocity]),
            rotation=rotation,
            orientation=orientation,
            angular_velocity=rotation.dot(x[self._omega]),
            acceleration=steady.acceleration,
            angular_acceleration=np.zeros(3) if omega_step is None else rotation.dot(omega_step),
            forces=steady.forces,
            site_forces=steady.site_forces,
        )
