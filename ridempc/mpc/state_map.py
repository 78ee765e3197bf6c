"""From the state estimate to the MPC's state vector, and the plan back to the world.

The MPC's state (the library's layout, named by ``state_names``) is built from the
:class:`~ridempc.estimation.EstimatedState` alone, never from the simulator:

- ``com_x, com_y, com_z`` [m], ``vx, vy, vz`` [m/s]: the whole robot's centre of mass and
  its velocity, :math:`c(q)` and :math:`J_c(q)\\,v` from Pinocchio at the estimated
  configuration;
- ``*_roll, *_pitch, *_yaw`` [rad] (trunk or pelvis): Z-Y-X Euler angles of the estimated
  base orientation, :math:`R = R_z(\\psi) R_y(\\vartheta) R_x(\\phi)`;
- ``wx, wy, wz`` [rad/s]: the base angular velocity in the base frame;
- ``q_<joint>`` [rad]: the encoders (through the estimator);
- board states, by their canonical quantity (:mod:`ridempc.boards.canonical`, the board's
  ``board_states``), from the platform estimates of the rider's feet
  (:class:`~ridempc.estimation.BoardEstimate`), one per platform in the board's platform
  order: ``x``, ``y`` [m] its origin, ``heading`` [rad], ``pitch`` [rad] (nose down
  positive), ``roll`` [rad], ``speed`` [m/s] forward speed
  :math:`\\dot c \\cdot (\\cos\\psi, \\sin\\psi)`, and the rates ``pitch_rate``,
  ``roll_rate``, ``yaw_rate`` [rad/s], differentiated from the angles through a first-order
  low-pass (``RATE_FILTER_HZ``).

**Library frame.** The library's trajectories start at the origin, heading along x. The map
keeps a planar transform :math:`(\\Delta\\psi, \\Delta p)` from the world to that frame,
:math:`p_{lib} = R_z(-\\Delta\\psi)(p - \\Delta p)`, set by :meth:`StateMap.anchor` so that
the estimated board pose lands on the reference's board pose at the moment a manoeuvre
starts; positions, velocities, headings and forces are carried through it both ways.
Between anchors :meth:`StateMap.follow_sideways` keeps the board on the reference's line
and within ``ALONG_SLACK`` of its place along it (the rider tracks commanded speeds and turn
rates, not a path).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.boards.canonical import BoardState
from ridempc.errors import ConfigError
from ridempc.estimation import EstimatedState
from ridempc.estimation.state import BoardEstimate
from ridempc.robots.pinocchio_model import PinocchioRobot
from ridempc.rotations import rpy_of_matrix, wrap_angle

__all__ = [
    "ALONG_SLACK",
    "GROUND_FILTER_S",
    "HEADING_FILTER_S",
    "HEADING_SPEED",
    "RATE_FILTER_HZ",
    "PlanarFrame",
    "StateMap",
    "forward_speed",
]

Array = NDArray[np.float64]
RATE_FILTER_HZ: float = 15.0  # [Hz] on the differentiated platform angles
HEADING_SPEED: float = 0.5  # [m/s] below this a board's direction of travel is not its heading
HEADING_FILTER_S: float = 0.3  # [s] time constant of the followed heading
ALONG_SLACK: float = 0.1  # [m] the board's offset along the reference's line is kept within
# [s] the followed ground's lag: a Hovershoe's 4 cm drop off a step is followed within a tenth
# of a second, its 4 Hz pitch's bobbing of the decks averaged out
GROUND_FILTER_S: float = 0.1
# [m] a rise of the ground the frame follows: the platforms' estimated height moves by up to
# 2.3 cm on level ground while a foot is off the deck (the dog's push-off), which is no terrain;
# once beyond it, the whole rise is followed until it is back within half of it. A platform
# under one foot (a Hovershoe) has no such excursion (its foot off, it has no estimate), so
# platforms that each carry one foot follow the whole rise at once
GROUND_DEADBAND_M: float = 0.03


def _along(velocity: Array, yaw: float) -> float:
    """A velocity's component along the heading ``yaw`` [rad]:
    :math:`v \\cdot (\\cos\\psi, \\sin\\psi)` [m/s]."""
    return float(velocity[0] * math.cos(yaw) + velocity[1] * math.sin(yaw))


def forward_speed(board: BoardEstimate) -> float:
    """The platform's speed along its heading, :math:`\\dot c \\cdot (\\cos\\psi, \\sin\\psi)`
    [m/s]."""
    return _along(board.velocity, board.yaw)


@dataclass(frozen=True)
class PlanarFrame:
    """World to library frame: :math:`p_{lib} = R_z(-\\Delta\\psi)(p - \\Delta p)`.

    Attributes:
        yaw: :math:`\\Delta\\psi` [rad].
        offset: :math:`\\Delta p` [m] (x, y).
        height: :math:`\\Delta p_z` [m], the ground's rise since the start under the
            platforms (:meth:`StateMap.follow_ground`).
    """

    yaw: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)
    height: float = 0.0

    def _rotation(self, sign: float) -> Array:
        c, s = math.cos(self.yaw), math.sin(sign * self.yaw)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    @classmethod
    def through(
        cls,
        yaw: float,
        library: Sequence[float] | Array,
        world: Sequence[float] | Array,
        height: float = 0.0,
    ) -> PlanarFrame:
        """The frame turned by ``yaw`` [rad] that puts the library point ``library`` on the
        world point ``world`` [m] (their x and y), ``height`` [m] above the library's."""
        c, s = math.cos(yaw), math.sin(yaw)
        return cls(
            yaw,
            (
                float(world[0] - (c * library[0] - s * library[1])),
                float(world[1] - (s * library[0] + c * library[1])),
            ),
            height,
        )

    def rotation(self) -> Array:
        """:math:`R_z(\\Delta\\psi)`, library axes to world axes."""
        return self._rotation(1.0)

    @cached_property
    def _to_world(self) -> Array:
        r""":math:`R_z(\Delta\psi)`, made once per frame (a frame is read several times a
        tick) and never handed out."""
        return self._rotation(1.0)

    @cached_property
    def _to_library(self) -> Array:
        r""":math:`R_z(-\Delta\psi)`, made once per frame and never handed out."""
        return self._rotation(-1.0)

    @cached_property
    def _shift(self) -> Array:
        r""":math:`\Delta p` [m] as a vector, made once per frame and never handed out."""
        return np.array([*self.offset, self.height])

    def point_to_library(self, p: Array) -> Array:
        shifted = np.asarray(p, dtype=float) - self._shift
        return self._to_library.dot(shifted)

    def vector_to_library(self, v: Array) -> Array:
        return self._to_library.dot(np.asarray(v, dtype=float))

    def point_to_world(self, p: Array) -> Array:
        return self._to_world.dot(np.asarray(p, dtype=float)) + self._shift

    def vector_to_world(self, v: Array) -> Array:
        return self._to_world.dot(np.asarray(v, dtype=float))


class _AngleRate:
    """:math:`\\dot a` from samples of :math:`a`, low-passed at ``hz`` (first order)."""

    def __init__(self, hz: float) -> None:
        self.hz = hz
        self.previous: tuple[float, float] | None = None
        self.rate = 0.0

    def __call__(self, time: float, angle: float) -> float:
        if self.previous is not None and time > self.previous[0]:
            dt = time - self.previous[0]
            raw = wrap_angle(angle - self.previous[1]) / dt
            alpha = 1.0 - math.exp(-2.0 * math.pi * self.hz * dt)
            self.rate += alpha * (raw - self.rate)
        self.previous = (time, angle)
        return self.rate


class StateMap:
    """Builds the MPC's state vector from estimates (see the module docstring).

    Args:
        robot: The rider's Pinocchio model.
        state_names: The pair's state layout.
        board_states: Per board state name, its platform (estimator order) and canonical
            quantity (:attr:`~ridempc.mpc.pairs.MpcPair.board_states`).
        base: The robot's base body (its description's ``base_body``): the states
            ``<base>_roll``, ``<base>_pitch``, ``<base>_yaw`` are its Z-Y-X angles.
        ground_rate_filter: The followed ground's rate's lag [s] (:meth:`follow_ground`).

    Raises:
        ConfigError: A state name the map cannot fill.
    """

    def __init__(
        self,
        robot: PinocchioRobot,
        state_names: Sequence[str],
        board_states: Mapping[str, BoardState],
        *,
        base: str,
        ground_rate_filter: float = GROUND_FILTER_S,
    ) -> None:
        self.robot = robot
        self.ground_rate_filter = ground_rate_filter
        self.base = base  # the base body, whose angles are ``<base>_roll`` ...
        self.data = robot.model.createData()
        self.names = tuple(state_names)
        self.board_states = board_states
        self.frame = PlanarFrame()
        self._rates: dict[str, _AngleRate] = {}
        self._heading_time = 0.0
        self._deck_start: float | None = None  # [m] the platforms' first height
        self._on_terrain = False  # the rise is beyond GROUND_DEADBAND_M (hysteresis)
        self._ground_time = 0.0
        self.ground_rate = 0.0  # [m/s] the followed ground's rise rate
        self._stance: list[int] = []  # the most feet each platform's estimate was taken from
        self._board_keys: dict[str, tuple[str, int, str]] = {}  # key: (key, platform, field)
        self._fill = [self._filler(name) for name in self.names]

    def _filler(self, name: str) -> tuple[str, int | str]:
        body = {"com_x": 0, "com_y": 1, "com_z": 2}
        if name in body:
            return ("com", body[name])
        if name in ("vx", "vy", "vz"):
            return ("com_velocity", "xyz".index(name[1]))
        if name in ("wx", "wy", "wz"):
            return ("omega", "xyz".index(name[1]))
        for k, angle in enumerate(("roll", "pitch", "yaw")):
            if name == f"{self.base}_{angle}":
                return ("base_angle", k)
        if name.startswith("q_"):
            return ("joint", name[2:])
        if name in self.board_states:
            platform, quantity = self.board_states[name]
            key = f"{platform}:{quantity}"
            index, field = key.split(":", 1)  # parsed once, not on each tick
            self._board_keys[key] = (key, int(index), field)
            return ("board", key)
        raise ConfigError(f"MPC state map: cannot estimate state '{name}'")

    def reset(self) -> None:
        self.frame = PlanarFrame()
        self._deck_start = None
        self._on_terrain = False
        self._ground_time = 0.0
        self.ground_rate = 0.0
        self._stance = []
        self._rates = {}
        self._heading_time = 0.0

    def _board_value(
        self,
        key: tuple[str, int, str],
        boards: tuple[BoardEstimate, ...],
        time: float,
        origins: dict[int, Array],
    ) -> float:
        """One board state of ``key`` (``platform:quantity``, the platform and the quantity);
        ``origins`` holds each platform's position in the library frame once found (one per
        :meth:`state`)."""
        name, k, field = key
        if k >= len(boards):
            raise ConfigError(f"MPC state map: no estimate of platform {k}")
        board = boards[k]
        heading = board.yaw - self.frame.yaw
        if k not in origins:
            origins[k] = self.frame.point_to_library(board.position)
        origin = origins[k]
        if field == "x":
            return float(origin[0])
        if field == "y":
            return float(origin[1])
        if field == "heading":
            return heading
        if field == "pitch":
            return board.pitch
        if field == "roll":
            return board.roll
        if field == "speed":
            return forward_speed(board)
        if field == "pitch_rate":
            angle = board.pitch
        elif field == "roll_rate":
            angle = board.roll
        elif field == "yaw_rate":
            angle = board.yaw
        else:
            raise ConfigError(f"MPC state map: unknown board state '{field}'")
        rate = self._rates.get(name)
        if rate is None:
            rate = self._rates[name] = _AngleRate(RATE_FILTER_HZ)
        return rate(time, angle)

    def state(self, estimate: EstimatedState) -> Array:
        """:math:`x_0` in the library frame, the pair's layout."""
        model, data = self.robot.model, self.data
        com = pin.centerOfMass(model, data, estimate.q, estimate.v)
        com_velocity = np.array(data.vcom[0])
        rotation = estimate.rotation
        roll, pitch, yaw = rpy_of_matrix(rotation)
        angles = (roll, pitch, wrap_angle(yaw - self.frame.yaw))
        com_lib = self.frame.point_to_library(com)
        velocity_lib = self.frame.vector_to_library(com_velocity)
        velocity_lib[2] -= self.ground_rate
        x = np.empty(len(self.names))
        origins: dict[int, Array] = {}
        for i, (kind, key) in enumerate(self._fill):
            if kind == "com":
                x[i] = com_lib[int(key)]
            elif kind == "com_velocity":
                x[i] = velocity_lib[int(key)]
            elif kind == "omega":
                x[i] = estimate.base_angular_velocity[int(key)]
            elif kind == "base_angle":
                x[i] = angles[int(key)]
            elif kind == "joint":
                x[i] = estimate.joint_position[str(key)]
            else:
                parsed = self._board_keys[str(key)]
                x[i] = self._board_value(parsed, estimate.boards, estimate.time, origins)
        return x

    def com(self, estimate: EstimatedState) -> Array:
        """The centre of mass in the world [m]."""
        return np.array(pin.centerOfMass(self.robot.model, self.data, estimate.q))

    def rider_speed(self, estimate: EstimatedState) -> float:
        """The centre of mass's speed along platform 0's heading (the base's heading without
        a board) [m/s]: :math:`\\dot c_{CoM} \\cdot (\\cos\\psi, \\sin\\psi)`."""
        pin.centerOfMass(self.robot.model, self.data, estimate.q, estimate.v)
        yaw = estimate.boards[0].yaw if estimate.boards else estimate.yaw
        return _along(self.data.vcom[0], yaw)

    def anchor(self, estimate: EstimatedState, board_pose: tuple[float, float, float]) -> None:
        """Set the frame so that platform 0's estimate lands on ``board_pose`` (x, y, yaw) of
        the reference."""
        board = estimate.boards[0] if estimate.boards else None
        if board is None:
            yaw_world, position = estimate.yaw, estimate.base_position
        else:
            yaw_world, position = board.yaw, board.position
        x_ref, y_ref, yaw_ref = board_pose
        self.frame = PlanarFrame.through(
            wrap_angle(yaw_world - yaw_ref), (x_ref, y_ref), position, self.frame.height
        )

    def follow_sideways(
        self,
        estimate: EstimatedState,
        board_pose: tuple[float, float, float],
        along: bool = False,
        heading: bool = False,
        slack: float = ALONG_SLACK,
        yaw_rate: float = 0.0,
    ) -> float:
        """Shift the frame across the reference's heading so that platform 0's estimate
        lies on the reference's line: its cross-track offset

        .. math:: e = n^\\top (p_{lib} - p_{ref}), \\qquad n = (-\\sin\\psi_{ref},
            \\cos\\psi_{ref})

        [m] becomes zero; heading is kept. A rider is commanded speeds and turn rates, not a
        line on the ground, and a board on wheels cannot move sideways but by turning: at 4
        m/s a heading error of 5 mrad carries the Segway 0.1 m off the reference's line in 5
        s, and the MPC, holding the rider's centre of mass on that line, leaned Cassie off
        her platform (velocity steps fell at 26.4 s). Offsets between the rider and the
        board are unchanged.

        The offset along the line, :math:`a = t^\\top (p_{lib} - p_{ref})` with :math:`t =
        (\\cos\\psi_{ref}, \\sin\\psi_{ref})`, is kept within ``slack`` [m], :math:`a
        \\leftarrow \\operatorname{clip}(a, -s, s)`: there it acts as the speed's integral.
        Beyond it, the MPC, which weighs the rider's and the boards' positions as tightly as
        their speeds, chases the position rather than the speed: on the Hovershoes at 0.5
        m/s the rider fell 1 m behind over 10 s, and the plans, to close it, ran the light
        shoes ahead of her and let her centre of mass slow down (velocity steps sagged to
        0.3 m/s, RMSE 0.237 m/s, and fell at 32.0 s; within 0.1 m: 0.173 m/s, and she rode
        it through).

        With ``along`` the offset along the line is taken out too (while turning: the
        reference's straight line is not the arc the board rides). With ``heading`` the
        frame first turns about the platform, keeping its place, so that the platform's
        direction of travel is the reference's heading: for a wheeled board whose heading
        the rider cannot steer (the Segway with its knee bar free), which a yaw-rate loop
        holds but nothing brings back. Its heading wandered by 0.08 rad in 1 s of braking
        from 4 m/s; the MPC held Cassie's pelvis and velocity on the reference's heading,
        and she stepped 0.24 m sideways off the board (velocity steps fell at 32.7 s). The
        direction of travel, :math:`\\operatorname{atan2}(\\dot c_y, \\dot c_x)` of the
        feet's velocity (wheels do not slide sideways), low-passed over
        ``HEADING_FILTER_S``, is the heading the feet can tell: the platform estimate's own
        yaw is the rider's (two feet side by side), and following it let the rider's yaw run
        off. Below ``HEADING_SPEED`` the frame does not turn.

        The followed heading is a complementary filter: over a tick of :math:`\\Delta t`
        the frame's yaw :math:`\\psi_f` is first carried by the turn rate ``yaw_rate``
        :math:`\\omega` [rad/s] (the rider's: the turn she commands), then drawn towards
        the direction of travel :math:`\\psi_{tr}`,

        .. math:: \\psi^- = \\psi_f + \\omega \\Delta t, \\qquad
            \\psi_f \\leftarrow \\psi^- + \\min(1, \\Delta t / T)\\,
            \\operatorname{wrap}(\\psi_{tr} - \\psi^-)

        with :math:`T` = ``HEADING_FILTER_S``: the travel sets the heading, the turn its
        changes. The low-pass alone lags a steady turn by :math:`\\omega T`, 0.15 rad at
        0.5 rad/s, and the MPC, holding the rider's pelvis and velocity on the lagging
        heading, leaned her out of the turn she was leaning into (Segway yaw-steps, seed
        0, the lean loop of before, :mod:`~ridempc.mpc.lean`: it held 0.5 rad/s with 0.35 m
        of reference offset; carried by the base gyro's yaw rate, with 0.12 m). The gyro
        carries the rider's own yaw into the frame her yaw is held in: riding straight
        (velocity-steps) her pelvis wandered up to 0.14 rad off the board, 0.016 rad
        carried by the commanded turn.

        Args:
            estimate: The state estimate.
            board_pose: The reference's platform 0 :math:`(x, y, \\psi)` [m, m, rad].
            along: Take out the offset along the line too.
            heading: Turn the frame onto platform 0's direction of travel.
            slack: :math:`s` [m].
            yaw_rate: :math:`\\omega` [rad/s], the turn that carries the followed heading
                (0: the plain low-pass).

        Returns:
            The shift :math:`e` [m] (0 without a board estimate).
        """
        if not estimate.boards:
            return 0.0
        x_ref, y_ref, yaw_ref = board_pose
        board = estimate.boards[0]
        vx, vy = float(board.velocity[0]), float(board.velocity[1])
        if heading and math.hypot(vx, vy) > HEADING_SPEED:
            travel = math.atan2(vy, vx)
            if forward_speed(board) < 0.0:
                travel = wrap_angle(travel + math.pi)
            wanted = wrap_angle(travel - yaw_ref)
            step = estimate.time - self._heading_time
            share = min(1.0, step / HEADING_FILTER_S)
            carried = self.frame.yaw + yaw_rate * step
            yaw = carried + share * wrap_angle(wanted - carried)
            kept = self.frame.point_to_library(board.position)
            self.frame = PlanarFrame.through(yaw, kept, board.position, self.frame.height)
        self._heading_time = estimate.time
        p_lib = self.frame.point_to_library(board.position)
        normal = np.array([-math.sin(yaw_ref), math.cos(yaw_ref), 0.0])
        gap = p_lib[:2] - np.array([x_ref, y_ref])
        error = float(normal[:2] @ gap)
        moved = error * normal
        if along:
            moved[:2] = gap
        else:
            tangent = np.array([math.cos(yaw_ref), math.sin(yaw_ref)])
            ahead = float(tangent @ gap)
            excess = ahead - min(max(ahead, -slack), slack)
            moved[:2] += excess * tangent
        shift = self.frame.vector_to_world(moved)
        offset = (self.frame.offset[0] + float(shift[0]), self.frame.offset[1] + float(shift[1]))
        self.frame = PlanarFrame(self.frame.yaw, offset, self.frame.height)
        return error

    def follow_ground(self, estimate: EstimatedState) -> float:
        """Raise the frame with the ground under the platforms: the library's rides are on
        level ground, and a rider kept at her starting height down a slope or a flight of
        steps stretched her legs after the shoes (stairs-79-93-93 fell at the third step).

        The rise is the platforms' mean estimated height (the feet's, from the IMU and the
        kinematics: no height map) over the first one seen, followed once beyond
        ``GROUND_DEADBAND_M`` (at once when each platform carries one foot) and low-passed
        over ``GROUND_FILTER_S``; its rate, the platforms' mean vertical velocity low-passed
        over ``ground_rate_filter`` (the same unless the pair sets it), comes off the centre
        of mass's (:meth:`state`), so that a rider rolling down a slope is not asked to stop
        sinking with it. A platform whose pitch swings (a Segway's firmware loop) swings its
        vertical velocity up a slope, :math:`\\dot v \\sin\\alpha`; a rate lagged
        beyond that swing's period keeps it out of the rider's vertical rate, while the
        height, lagged as before, keeps the frame on the incline (lagged 1 s, it trailed the
        Segway's 10 deg climb by 17 cm). Without a board estimate nothing changes.

        Returns:
            The frame's height :math:`\\Delta p_z` [m].
        """
        if not estimate.boards:
            return self.frame.height
        deck = sum(float(b.position[2]) for b in estimate.boards) / len(estimate.boards)
        if self._deck_start is None:
            self._deck_start, self._ground_time = deck, estimate.time
        elapsed = max(0.0, estimate.time - self._ground_time)
        share = min(1.0, elapsed / GROUND_FILTER_S)
        rate_share = min(1.0, elapsed / self.ground_rate_filter)
        self._ground_time = estimate.time
        rise = deck - self._deck_start
        feet = [len(b.feet) for b in estimate.boards]
        if len(feet) != len(self._stance):
            self._stance = feet
        self._stance = [max(a, b) for a, b in zip(self._stance, feet, strict=True)]
        if abs(rise) > GROUND_DEADBAND_M or all(n == 1 for n in self._stance):
            self._on_terrain = True
        elif abs(rise) < 0.5 * GROUND_DEADBAND_M:
            self._on_terrain = False
        followed = rise if self._on_terrain else 0.0
        height = self.frame.height + share * (followed - self.frame.height)
        sinking = 0.0
        if self._on_terrain:
            sinking = sum(float(b.velocity[2]) for b in estimate.boards) / len(estimate.boards)
        self.ground_rate += rate_share * (sinking - self.ground_rate)
        self.frame = PlanarFrame(self.frame.yaw, self.frame.offset, height)
        return height
