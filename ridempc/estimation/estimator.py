"""The 500 Hz state estimator: IMU attitude, encoder joints, leg odometry fused with the VIO.

Each tick, from one :class:`~ridempc.sim.sensors.SensorPacket` (never its ``truth``):

1. **Attitude** (:mod:`~ridempc.estimation.imu`): :math:`R_{WB} = R_{WS} R_{BS}^\\top`,
   :math:`\\omega_B = R_{BS}\\, \\omega_S` and the IMU point's acceleration
   :math:`a = R_{WS} f_S + g`, with the IMU's placement read from the description.
2. **Joints** (:mod:`~ridempc.estimation.joints`, :mod:`~ridempc.estimation.loop_closure`):
   the encoders, and the unmeasured joints of closed chains solved from their closure.
3. **Legs** (:mod:`~ridempc.estimation.legs`): each foot's position and velocity relative
   to the base, and the IMU point's.
4. **Contact** (:mod:`~ridempc.estimation.contact`): each foot's load from spring
   deflection or joint torques, through a Schmitt trigger.
5. **Filter** (:mod:`~ridempc.estimation.leg_odometry`, :mod:`~ridempc.estimation.kalman`):
   predict with :math:`a`; update with the stance feet's kinematics; when a new VIO sample
   has arrived, update with it against the state at its capture stamp
   (:mod:`~ridempc.estimation.history`).
6. **Board** (:mod:`~ridempc.estimation.board`): when told which feet stand on a board,
   each platform's pose and velocity from those of its feet in contact (from all of them
   when none is); a foot the controller puts on the ground (:meth:`set_support`, a push-off)
   stands still and is left out, as is a foot the schedule has in the air.

Orientation comes from the IMU alone: the simulated IMU's orientation error is white,
with no drift to correct, so the VIO's yaw is not used.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import MappingProxyType

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.errors import ConfigError
from ridempc.estimation.board import estimate_board
from ridempc.estimation.contact import ContactDetector, build_contact_detector
from ridempc.estimation.history import HistoryEntry, StateHistory
from ridempc.estimation.imu import BaseAttitude, ImuMount
from ridempc.estimation.joints import JointMap
from ridempc.estimation.kalman import LinearKalmanFilter
from ridempc.estimation.leg_odometry import LegOdometryModel
from ridempc.estimation.legs import LegKinematics, LegReading
from ridempc.estimation.loop_closure import LoopClosure
from ridempc.estimation.parameters import EstimatorParameters
from ridempc.estimation.state import BoardEstimate, EstimatedState, JointValues
from ridempc.robots.pinocchio_model import PinocchioRobot, build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.rotations import matrix_of_rpy
from ridempc.sim.sensors import SensorPacket, VioReading

__all__ = ["StateEstimator"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]


def _check_feet(what: str, names: Sequence[str], feet: Sequence[str]) -> None:
    """Raises ConfigError: one of ``names`` is not among ``feet``."""
    unknown = [f for f in names if f not in feet]
    if unknown:
        raise ConfigError(f"{what} '{unknown[0]}' is not a foot (valid: {', '.join(feet)})")


class StateEstimator:
    """Estimates the rider's state from its sensor packets.

    Args:
        robot: The robot.
        params: Noise model and thresholds.
        platforms: The feet standing on each moving board platform (one group per platform:
            the skateboard's deck, each hovershoe). Their support velocity is free, and
            :attr:`EstimatedState.boards` holds one estimate per group. Empty on the ground.
        pinocchio: The robot's Pinocchio model (built from ``robot`` if not given).
        support_height: Height of the surface the feet stand on when the estimator starts
            [m]: a board's deck top at rest (:attr:`~ridempc.boards.Board.platform_top`),
            0 on the ground. Until the first VIO sample arrives it is the only height prior.

    Raises:
        ConfigError: A name in ``platforms`` is not a foot or is in two groups, or the
            robot's description does not suit the chosen contact signal.
    """

    def __init__(
        self,
        robot: Robot,
        params: EstimatorParameters | None = None,
        platforms: Sequence[Sequence[str]] = (),
        pinocchio: PinocchioRobot | None = None,
        support_height: float = 0.0,
    ) -> None:
        self.robot = robot
        self.support_height = float(support_height)
        self.params = params or EstimatorParameters()
        self.pinocchio = pinocchio or build_pinocchio_robot(robot)
        self.model: pin.Model = pin.Model(self.pinocchio.model)  # a copy: closures add frames
        self.mount = ImuMount.from_pinocchio(self.pinocchio, robot.params.imu_site)
        self.joints = JointMap.build(self.model, robot.encoder_joints)
        self.closure = LoopClosure.build(
            self.model, self.pinocchio.constraints, self.joints.unmeasured_v
        )
        self.data: pin.Data = self.model.createData()
        self._hinge_index = MappingProxyType(
            {name: k for k, name in enumerate(self.joints.hinge_names)}
        )
        self._closes_loops = self.closure.active
        self._nv = self.model.nv
        self.legs = LegKinematics.build(robot, self.pinocchio)
        feet = self.legs.names
        on_board = [f for group in platforms for f in group]
        _check_feet("platform foot", on_board, feet)
        if len(set(on_board)) != len(on_board):
            raise ConfigError(f"a foot stands on two platforms: {[list(g) for g in platforms]}")
        self.platforms = tuple(tuple(group) for group in platforms if group)
        self._on_board = np.array([f in on_board for f in feet])
        self._on_ground = ~self._on_board
        self._swinging = np.zeros(len(feet), dtype=bool)
        self._platform_sites = tuple(
            np.isin(self.legs.site_foot, [feet.index(f) for f in group]) for group in self.platforms
        )
        self._platform_rows = tuple(np.flatnonzero(sites) for sites in self._platform_sites)
        self._board_feet_cache: dict[bytes, tuple[tuple[tuple[str, ...], Index, bool], ...]] = {}
        # Each contact site's place on its platform (platform frame, from the centroid of all
        # the platform's sites), as last seen with every one of them down; NaN before that.
        self._footprints = np.full((len(self.legs.site_foot), 3), np.nan)
        self.contact: ContactDetector = build_contact_detector(
            robot, self.pinocchio, self.legs, self.params
        )
        self.odometry = LegOdometryModel(len(feet), self.params)
        self.history = StateHistory(self.params.history)
        self._q_guess = self.pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
        self.filter = LinearKalmanFilter(np.zeros(self.odometry.size), np.eye(self.odometry.size))
        self._time = 0.0
        self._acceleration = np.zeros(3)
        self._vio_stamp: float | None = None
        self.state: EstimatedState | None = None
        self.rejected_feet = 0  # stance-foot velocities left out as outliers, since reset

    def set_support(self, on_ground: Sequence[str], swinging: Sequence[str] = ()) -> None:
        """Which of the platforms' feet stand on the ground now instead of their board (a
        skateboard push-off), and which are planned in the air; the rest stand on their
        boards again. A foot on the ground has a still support and says nothing of its
        board's pose; a swinging foot says nothing of it either, even when it touches down
        early (the dog's pusher met the ground 0.06 s before its schedule: taken for a deck
        foot, it moved the deck's estimate 3.7 cm sideways for the rest of the ride).

        Raises:
            ConfigError: A name is not a foot.
        """
        feet = self.legs.names
        _check_feet("support:", on_ground, feet)
        _check_feet("support:", swinging, feet)
        # membership per foot name (np.isin sorts both lists: 10 us a call on a few names)
        self._on_ground = ~self._on_board | np.array([f in on_ground for f in feet], dtype=bool)
        self._swinging = np.array([f in swinging for f in feet], dtype=bool)

    def _sense(self, packet: SensorPacket) -> tuple[BaseAttitude, Array, Array, LegReading]:
        """Steps 1-3: attitude, joints and legs of one packet."""
        imu = packet.imu
        attitude = self.mount.attitude(
            imu.quaternion, imu.angular_velocity, imu.linear_acceleration
        )
        q = self._q_guess.copy()
        v = np.zeros(self._nv)
        self.joints.write(
            q,
            v,
            attitude.quaternion,
            attitude.angular_velocity,
            packet.joint_position,
            packet.joint_velocity,
        )
        if self._closes_loops:
            q, v = self.closure.solve(self.model, self.data, q, v)
            self._q_guess = q
        else:
            pin.computeJointJacobians(self.model, self.data, q)
        return attitude, q, v, self.legs.read(self.model, self.data, v)

    def reset(self, packet: SensorPacket, base_position: Array | None = None) -> EstimatedState:
        """Start from the first packet, the robot at rest.

        Args:
            packet: The first sensor packet.
            base_position: Prior base position [m], held with the parameters' wide initial
                standard deviations. Default: the VIO's if a sample has arrived (held at
                the VIO's), otherwise horizontal zero with the lowest contact point on a
                support at :math:`z` = ``support_height`` (the board's deck top at rest, 0 on
                the ground).
        """
        attitude, q, v, legs = self._sense(packet)
        self.contact.contact[:] = True
        stance = self.contact.update(
            self.model, self.data, q, packet.joint_position, packet.motor_torque, legs
        )
        from_vio = base_position is None and packet.vio is not None
        if base_position is not None:
            prior = np.asarray(base_position, dtype=float)
        elif packet.vio is not None:
            prior = np.array(packet.vio.position, dtype=float)
        else:
            prior = np.array(
                [0.0, 0.0, self.support_height - float(np.min(legs.site_position[:, 2]))]
            )
        x, P = self.odometry.initial_state(
            prior + legs.imu_position,
            np.zeros(3),
            legs.foot_position - legs.imu_position,
            height_known=from_vio,
        )
        self.filter = LinearKalmanFilter(x, P)
        self.history.clear()
        self.rejected_feet = 0
        self._footprints[:] = np.nan
        self._time = packet.time
        self._acceleration = attitude.imu_acceleration
        self._vio_stamp = packet.vio.stamp if packet.vio is not None else None
        self.history.append(
            HistoryEntry(packet.time, x.copy(), legs.imu_position, legs.imu_velocity)
        )
        self.state = self._output(packet.time, attitude, q, v, legs, stance)
        return self.state

    def update(self, packet: SensorPacket) -> EstimatedState:
        """One estimator tick (calls :meth:`reset` on the first packet)."""
        if self.state is None:
            return self.reset(packet)
        attitude, q, v, legs = self._sense(packet)
        stance = self.contact.update(
            self.model, self.data, q, packet.joint_position, packet.motor_torque, legs
        )
        dt = packet.time - self._time
        if dt > 0.0:
            acceleration = 0.5 * (self._acceleration + attitude.imu_acceleration)
            self.filter.predict(*self.odometry.process(dt, acceleration, stance, self._on_ground))
        self._time, self._acceleration = packet.time, attitude.imu_acceleration
        leg = self.odometry.legs(
            legs.foot_position - legs.imu_position,
            legs.foot_velocity - legs.imu_velocity,
            stance,
        )
        _, rejected = self.filter.update(
            leg.H, leg.z, leg.R, gated=leg.gated, gate=self.params.velocity_gate
        )
        self.rejected_feet += rejected
        # the filter's x as it is: the filter rebinds its mean, never writes into it
        self.history.append(
            HistoryEntry(packet.time, self.filter.x, legs.imu_position, legs.imu_velocity)
        )
        vio = packet.vio
        if vio is not None and vio.stamp != self._vio_stamp:
            self._vio_stamp = vio.stamp
            self._fuse_vio(vio)
        self.state = self._output(packet.time, attitude, q, v, legs, stance)
        return self.state

    def _fuse_vio(self, vio: VioReading) -> None:
        """Fuse a VIO sample against the state at its capture stamp."""
        past = self.history.at(vio.stamp)
        if past is None:  # older than the history: too late to use
            return
        measurement = self.odometry.vio(
            vio.position + past.imu_offset, vio.velocity + past.imu_offset_rate
        )
        correction, _ = self.filter.update(
            measurement.H, measurement.z, measurement.R, predicted=past.x[:6]
        )
        self.history.shift_after(vio.stamp, correction)

    def _board_feet(
        self, stance: NDArray[np.bool_]
    ) -> tuple[tuple[tuple[str, ...], Index, bool], ...]:
        """Per platform, the feet that say where it is, the rows of their contact sites and
        whether the platform carries one foot only: the feet on it, and of those the ones in
        contact if any is. Cached per contact and support pattern (at most 8^feet):
        selecting them anew cost 20 us a tick."""
        key = stance.tobytes() + self._on_ground.tobytes() + self._swinging.tobytes()
        selection = self._board_feet_cache.get(key)
        if selection is None:
            names, site_foot = self.legs.names, self.legs.site_foot
            on_board = ~self._on_ground & ~self._swinging
            in_stance = stance & on_board
            chosen = []
            for group, sites in zip(self.platforms, self._platform_sites, strict=True):
                alone = len(group) == 1
                for reading in (in_stance, on_board):
                    if np.any(sites & reading[site_foot]):
                        sites = sites & reading[site_foot]
                        group = tuple(f for f in group if reading[names.index(f)])
                        break
                chosen.append((group, np.flatnonzero(sites), alone))
            selection = self._board_feet_cache[key] = tuple(chosen)
        return selection

    def _platform(
        self,
        group: tuple[str, ...],
        rows: Index,
        alone: bool,
        points: Array,
        velocities: Array,
        forward: Array,
        full: Index,
    ) -> BoardEstimate:
        """One platform's estimate from the sites ``rows`` of its sites ``full``: with all of
        them down it records where each site sits on the platform (on a platform of several
        feet: ``alone``, one foot's are never read); with some feet, their
        recorded places put the origin where all of them would have it. With one foot left
        the origin stays at it, as before: with the footprint there too, the Segway's
        velocity-steps fell at 20.1 s instead of 32.7 s, after the first moment (at 19 s,
        3.5 m/s) that one of Cassie's feet unloaded; why is not yet understood."""
        footprint = None
        partial = len(rows) < len(full)
        if partial and len(group) > 1:
            known = self._footprints[rows]
            if np.all(np.isfinite(known)):
                footprint = known.sum(axis=0) / len(rows)
        board = estimate_board(
            group, points, velocities, forward=forward, own_platform=alone, footprint=footprint
        )
        if not partial and len(rows) > 1 and not alone:  # one foot's are never read
            rotation = matrix_of_rpy(board.roll, board.pitch, board.yaw)
            self._footprints[rows] = (points - board.position) @ rotation
        return board

    def _output(
        self,
        time: float,
        attitude: BaseAttitude,
        q: Array,
        v: Array,
        legs: LegReading,
        stance: NDArray[np.bool_],
    ) -> EstimatedState:
        x = self.filter.x
        base_position = x[:3] - legs.imu_position
        base_velocity = x[3:6] - legs.imu_velocity
        q = q.copy()  # q is also the next tick's loop-closure guess; v is this tick's own
        q[:3] = base_position
        v[:3] = attitude.rotation.T @ base_velocity
        boards: tuple[BoardEstimate, ...] = ()
        if self.platforms:  # every site at once, not per platform
            site_position = base_position + legs.site_position
            site_velocity = base_velocity + legs.site_velocity
            boards = tuple(
                self._platform(
                    group,
                    rows,
                    alone,
                    site_position[rows],
                    site_velocity[rows],
                    attitude.rotation[:, 0],
                    full,
                )
                for (group, rows, alone), full in zip(
                    self._board_feet(stance), self._platform_rows, strict=True
                )
            )
        return EstimatedState(
            time=time,
            base_position=base_position,
            base_quaternion=attitude.quaternion,
            base_velocity=base_velocity,
            base_angular_velocity=attitude.angular_velocity,
            joint_position=JointValues(self._hinge_index, q[self.joints.hinge_q]),
            joint_velocity=JointValues(self._hinge_index, v[self.joints.hinge_v]),
            q=q,
            v=v,
            foot_names=self.legs.names,
            contact=stance,
            foot_position=self.odometry.foot_positions(x),
            foot_velocity=base_velocity + legs.foot_velocity,
            boards=boards,
        )
