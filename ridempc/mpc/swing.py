"""Swing-foot targets from the motion library's reference, carried by the board.

A library with joint angles among its states (the quadruped's single rigid body plus
kinematics) plans where every foot goes. A foot the schedule lifts follows that plan:

1. **The reference's foot.** At reference time :math:`t` the state gives the centre of mass
   :math:`c` [m], the trunk's Z-Y-X angles :math:`(\\phi, \\vartheta, \\psi)` [rad] and the
   joint angles :math:`q_j` [rad]. Forward kinematics with the base at the origin, turned
   by :math:`R = R_z(\\psi) R_y(\\vartheta) R_x(\\phi)`, gives each foot's point
   :math:`p^0_f(q)` and the centre of mass :math:`c^0(q)`; the foot in the library frame is

   .. math:: p_f = c + p^0_f(q) - c^0(q).

2. **Carried by the board.** The reference's board pose :math:`(x_b, y_b, \\psi_b)` and the
   estimated one :math:`(\\hat x_b, \\hat y_b, \\hat\\psi_b)` (library frame) move the target
   in the plane with the board, its height as planned:

   .. math:: p^*_{f,xy} = \\hat p_b + R_z(\\hat\\psi_b - \\psi_b)\\,(p_{f,xy} - p_b),
             \\qquad p^*_{f,z} = p_{f,z}.

   A foot returning to the deck lands where the plan puts it on the deck, and a foot
   pushing reaches down to the ground, whatever the trunk's height error. Read off the
   MPC's first step at the estimated trunk instead (the previous rule), the foot followed
   the trunk: a trunk 4 cm above its plan held the pushing foot 9 cm above the ground when
   the schedule put it down, and after the push the foot dragged on the ground.

3. **Velocity** [m/s]: the estimated board's velocity plus the reference foot's velocity
   relative to the reference board, turned likewise (a forward difference of the
   reference over ``VELOCITY_STEP``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.estimation.state import BoardEstimate
from ridempc.mpc.state_map import PlanarFrame
from ridempc.trajopt.rotations import euler_zyx_matrix
from ridempc.wbc.model import WholeBodyModel

__all__ = ["VELOCITY_STEP", "ReferenceFeet"]

Array = NDArray[np.float64]
VELOCITY_STEP: float = 0.01  # [s] forward difference of the reference's feet


class ReferenceFeet:
    """The reference's feet, for swing targets (see the module docstring).

    Args:
        model: The whole-body model (its Pinocchio model and foot points).
        state_names: The library's state names.
        base_prefix: Prefix of the trunk's angles (``trunk_``).
        board_pose: The first platform's (x, y, heading) in a library state.
    """

    def __init__(
        self,
        model: WholeBodyModel,
        state_names: Sequence[str],
        base_prefix: str,
        board_pose: Callable[[Array], tuple[float, float, float]],
    ) -> None:
        self.model = model
        self._data = model.model.createData()
        names = {name: i for i, name in enumerate(state_names)}
        pin_model = model.model
        self._joints = [
            (i, pin_model.joints[pin_model.getJointId(name[2:])].idx_q)
            for name, i in names.items()
            if name.startswith("q_")
        ]
        self._state_of_q = {index: i for i, index in self._joints}
        # the same pairs as two index arrays: the joints written in one assignment
        self._joint_rows = np.array([i for i, _ in self._joints], dtype=np.int64)
        self._joint_q = np.array([index for _, index in self._joints], dtype=np.int64)
        self._rows: dict[bytes, NDArray[np.int64]] = {}  # state rows per order of the motors
        self._com = [names[f"com_{a}"] for a in "xyz"]
        self._angles = [names[f"{base_prefix}{a}"] for a in ("roll", "pitch", "yaw")]
        self._board_pose = board_pose
        self._q = pin.neutral(pin_model)

    def joint_angles(self, state: Array, motor_q: NDArray[np.int64]) -> Array:
        """The state's joint angles [rad] in the order of ``motor_q`` (configuration
        indices)."""
        key = motor_q.tobytes()
        rows = self._rows.get(key)
        if rows is None:  # one order of the motors per rider
            rows = self._rows[key] = np.array([self._state_of_q[int(k)] for k in motor_q])
        return np.asarray(state[rows], dtype=float)

    @property
    def plans_feet(self) -> bool:
        """Whether the library's states carry joint angles (else nothing to follow)."""
        return bool(self._joints)

    def points(self, state: Array) -> Array:
        """:math:`p_f` of every foot in the library frame [m], shape (feet, 3)."""
        q = self._q
        q[self._joint_q] = state[self._joint_rows]
        roll, pitch, yaw = (float(state[i]) for i in self._angles)
        rotation = euler_zyx_matrix(roll, pitch, yaw)
        q[:3] = 0.0
        q[3:7] = pin.Quaternion(rotation).coeffs()  # x, y, z, w
        com = pin.centerOfMass(self.model.model, self._data, q)  # the joints placed at q
        return self.model.placed_foot_points(self._data) - com + state[self._com]

    def targets(
        self, states: Array, frame: PlanarFrame, board: BoardEstimate | None
    ) -> tuple[Array, Array]:
        """Swing targets from the reference's states at :math:`t` and
        :math:`t +` ``VELOCITY_STEP`` (``MotionReference.states_at``):
        world positions [m] and velocities [m/s] of every foot, shape (feet, 3) each."""
        ends = []
        if board is not None:  # the estimated board in the library frame, for both states
            place = frame.point_to_library(board.position)
            heading = board.yaw - frame.yaw
        for state in states[:2]:
            feet = self.points(state)
            if board is not None:
                x_b, y_b, psi_b = self._board_pose(state)
                turn = heading - psi_b
                c, s = math.cos(turn), math.sin(turn)
                dx, dy = feet[:, 0] - x_b, feet[:, 1] - y_b
                feet[:, 0] = place[0] + c * dx - s * dy
                feet[:, 1] = place[1] + s * dx + c * dy
            ends.append(np.array([frame.point_to_world(p) for p in feet]))
        velocity = (ends[1] - ends[0]) / VELOCITY_STEP  # relative to the board when carried
        if board is not None:
            velocity[:, :2] += board.velocity[:2]
        return ends[0], velocity
