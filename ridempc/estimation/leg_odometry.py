"""The linear filter's model: IMU-driven process, stance-foot kinematics and VIO measurements.

In the style of the MIT Cheetah / legged_control linear Kalman filter, the state is the
IMU point :math:`p_S` (not the base origin, so that the accelerometer, which measures
the IMU point, drives it with no lever-arm term), its velocity, and per foot :math:`i`
its position :math:`p_i` and the velocity :math:`u_i` of the support under it, all in the
world frame:

.. math::

    x = (p_S,\\ \\dot p_S,\\ p_1,\\ u_1,\\ \\dots,\\ p_n,\\ u_n) \\in \\mathbb{R}^{6 + 6n}.

Process (``dt`` [s], IMU acceleration :math:`a = R_{WS} f_S + g` [m/s^2]):

.. math::

    p_S^+ = p_S + \\dot p_S\\, dt + \\tfrac12 a\\, dt^2, \\quad
    \\dot p_S^+ = \\dot p_S + a\\, dt, \\quad
    p_i^+ = p_i + u_i\\, dt, \\quad u_i^+ = \\alpha_i u_i,

with white acceleration noise on :math:`\\dot p_S` and a random walk on each foot (large for
a foot in the air, so that it follows the leg). The support velocity is what lets a foot
stand on a moving board. On a board it is a random walk (:math:`\\alpha_i = 1`), the board's
velocity. On the ground it is a first-order Gauss-Markov process about zero,
:math:`\\alpha_i = e^{-dt/\\tau}`, of stationary standard
deviation :math:`\\sigma_u` (``static_support_std``): the ground is still but a foot may
slip or roll a little, for a while (``support_correlation_time`` :math:`\\tau`).

Measurements, per foot (from :class:`~ridempc.estimation.legs.LegReading`):

.. math::

    p_i - p_S = d_i - d_S \\quad \\text{(every foot)}, \\qquad
    \\dot p_S - u_i = -(w_i - w_S) \\quad \\text{(stance)},

and from the VIO (base position :math:`p_B` and velocity :math:`\\dot p_B` [m, m/s]) at
its capture time, moved to the IMU point: :math:`p_S = p_B + d_S`,
:math:`\\dot p_S = \\dot p_B + w_S`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation.parameters import EstimatorParameters

__all__ = ["LegOdometryModel", "Measurement"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]
I3 = np.eye(3)


@dataclass(frozen=True)
class Measurement:
    """A stacked linear measurement :math:`z = H x + n`, :math:`n \\sim N(0, R)`.

    Attributes:
        H: Measurement matrix.
        z: Measurement.
        R: Its covariance.
        gated: Row groups to test for outliers before fusing (stance-foot velocities),
            shape (groups, 3).
    """

    H: Array
    z: Array
    R: Array
    gated: NDArray[np.int64] | None = None


@dataclass(frozen=True)
class LegOdometryModel:
    """Builds the filter's matrices for ``feet`` feet.

    Attributes:
        feet: Number of feet :math:`n`.
        params: Noise densities and standard deviations.
    """

    feet: int
    params: EstimatorParameters

    @property
    def size(self) -> int:
        return 6 + 6 * self.feet

    @staticmethod
    def foot_position(i: int) -> slice:
        return slice(6 + 6 * i, 9 + 6 * i)

    @staticmethod
    def support_velocity(i: int) -> slice:
        return slice(9 + 6 * i, 12 + 6 * i)

    def foot_positions(self, x: Array) -> Array:
        """Every foot's :math:`p_i` in a state ``x`` [m], shape (feet, 3)."""
        return x[6:].reshape(self.feet, 6)[:, :3].copy()

    def initial_state(
        self, imu_position: Array, imu_velocity: Array, foot_offsets: Array, height_known: bool
    ) -> tuple[Array, Array]:
        """Mean and covariance of the prior.

        Args:
            imu_position: Prior :math:`p_S` [m].
            imu_velocity: Prior :math:`\\dot p_S` [m/s].
            foot_offsets: :math:`d_i - d_S` per foot [m], shape (feet, 3).
            height_known: True if ``imu_position`` comes from a position measurement.
        """
        p = self.params
        x = np.zeros(self.size)
        x[:3], x[3:6] = imu_position, imu_velocity
        base_std = np.array([p.initial_position_std, p.initial_position_std, p.initial_height_std])
        if height_known:
            base_std[:] = p.vio_position_std
        P_pp = np.diag(base_std**2)
        P = np.zeros((self.size, self.size))
        P[:3, :3] = P_pp
        P[3:6, 3:6] = p.initial_velocity_std**2 * I3
        # a foot is where its leg puts it, p_i = p_S + (d_i - d_S) + n_i: every position shares
        # the uncertainty of p_S
        positions = [slice(0, 3)] + [self.foot_position(i) for i in range(self.feet)]
        for a in positions:
            for b in positions:
                P[a, b] = P_pp
        for i in range(self.feet):
            f, u = self.foot_position(i), self.support_velocity(i)
            x[f] = imu_position + foot_offsets[i]
            P[f, f] += p.kinematic_position_std**2 * I3
            P[u, u] = p.static_support_std**2 * I3  # the first packet finds the robot at rest
        return x, P

    def process(
        self,
        dt: float,
        acceleration: Array,
        stance: NDArray[np.bool_],
        on_ground: NDArray[np.bool_],
    ) -> tuple[Array, Array, Array]:
        """:math:`(F, b, Q)` of one step of ``dt`` [s] under IMU acceleration [m/s^2].

        Args:
            dt: Step [s].
            acceleration: :math:`a` [m/s^2], world.
            stance: Feet in contact.
            on_ground: Feet whose support is the (still) ground, not a board.
        """
        F, Q = self._process_matrices(float(dt), stance.tobytes(), on_ground.tobytes())
        b = np.zeros(self.size)
        b[:3] = 0.5 * dt**2 * acceleration
        b[3:6] = dt * acceleration
        return F, b, Q

    @functools.lru_cache(maxsize=64)  # noqa: B019 - few (dt, stance) patterns, long-lived model
    def _process_matrices(self, dt: float, stance_key: bytes, ground_key: bytes):
        stance = np.frombuffer(stance_key, dtype=bool)
        on_ground = np.frombuffer(ground_key, dtype=bool)
        p = self.params
        alpha = float(np.exp(-dt / p.support_correlation_time))
        F = np.eye(self.size)
        F[:3, 3:6] = dt * I3
        Q = np.zeros((self.size, self.size))
        sa2 = p.accel_std**2  # continuous white acceleration of density sa2 [m^2/s^3]
        Q[:3, :3] = sa2 * dt**3 / 3.0 * I3
        Q[:3, 3:6] = Q[3:6, :3] = sa2 * dt**2 / 2.0 * I3
        Q[3:6, 3:6] = sa2 * dt * I3
        for i in range(self.feet):
            f, u = self.foot_position(i), self.support_velocity(i)
            F[f, u] = dt * I3
            walk = p.foot_position_std if stance[i] else p.swing_position_std
            Q[f, f] = walk**2 * dt * I3
            if on_ground[i]:
                F[u, u] = alpha * I3
                Q[u, u] = p.static_support_std**2 * (1.0 - alpha**2) * I3
            else:
                Q[u, u] = p.support_accel_std**2 * dt * I3
        F.flags.writeable = False
        Q.flags.writeable = False
        return F, Q

    def legs(
        self, foot_offsets: Array, foot_velocities: Array, stance: NDArray[np.bool_]
    ) -> Measurement:
        """The leg kinematics measurements of one tick.

        Args:
            foot_offsets: :math:`d_i - d_S` [m], shape (feet, 3).
            foot_velocities: :math:`w_i - w_S` [m/s], shape (feet, 3).
            stance: Feet in contact.
        """
        H, R, gated, position_rows = self._leg_matrices(stance.tobytes())
        z = np.empty((H.shape[0] // 3, 3))  # one row a 3-vector, in H's order
        z[position_rows] = foot_offsets
        z[gated[:, 0] // 3] = -foot_velocities[stance]
        return Measurement(H=H, z=z.ravel(), R=R, gated=gated)

    @functools.lru_cache(maxsize=64)  # noqa: B019 - at most 2^feet patterns
    def _leg_matrices(self, stance_key: bytes) -> tuple[Array, Array, Index, Index]:
        """:math:`(H, R)` of the leg measurements in :meth:`legs`'s row order (per foot its
        position, then its velocity if in stance), the row groups of the stance-foot
        velocities (tested for outliers) and the 3-row blocks of the foot positions."""
        stance = np.frombuffer(stance_key, dtype=bool)
        p = self.params
        blocks: list[list[tuple[slice, Array]]] = []
        stds: list[float] = []
        gated: list[range] = []
        positions: list[int] = []
        for i in range(self.feet):
            f, u = self.foot_position(i), self.support_velocity(i)
            positions.append(len(blocks))
            blocks.append([(f, I3), (slice(0, 3), -I3)])
            stds.append(p.kinematic_position_std)
            if stance[i]:
                gated.append(range(3 * len(blocks), 3 * len(blocks) + 3))
                blocks.append([(slice(3, 6), I3), (u, -I3)])
                stds.append(p.kinematic_velocity_std)
        H = np.zeros((3 * len(blocks), self.size))
        for row, pieces in enumerate(blocks):
            for where, block in pieces:
                H[3 * row : 3 * row + 3, where] = block
        R = np.diag(np.repeat(np.square(stds), 3))
        rows = np.array(gated, dtype=np.int64).reshape(-1, 3)
        position_rows = np.array(positions, dtype=np.int64)
        for array in (H, R, rows, position_rows):
            array.flags.writeable = False
        return H, R, rows, position_rows

    def vio(self, imu_position: Array, imu_velocity: Array) -> Measurement:
        """The VIO measurement of :math:`p_S` [m] and :math:`\\dot p_S` [m/s]."""
        H, R = self._vio_matrices
        return Measurement(H=H, z=np.concatenate([imu_position, imu_velocity]), R=R)

    @functools.cached_property
    def _vio_matrices(self) -> tuple[Array, Array]:
        p = self.params
        H = np.zeros((6, self.size))
        H[:, :6] = np.eye(6)
        R = np.diag(np.repeat([p.vio_position_std**2, p.vio_velocity_std**2], 3))
        H.flags.writeable = False
        R.flags.writeable = False
        return H, R
