"""The Hovershoes and the Segway as the optimisation sees them: their reduced models in CasADi.

Both are self-balancing platforms whose firmware turns the rider's pitch torque into a
platform pitch and the pitch into forward acceleration; the reduced models (identified in
``boards/<name>/board.toml``) are reused with ``xp = casadi``:

- :class:`HovershoesBoard`: two shoes, each :mod:`ridempc.boards.hovershoes.reduced`
  (eq. 4-8 of the hovershoe paper) driven by the torques of eq. (9) from the foot on it,
  and by the foot's push along the shoe (eq. 8 below);
- :class:`SegwayBoard`: one platform, :mod:`ridempc.boards.segway.reduced` (eq. 4', 5',
  8'), driven by the rider's pitch torque (eq. 9) and the knee-bar angle, an input here.

A platform's frame has its origin at the top centre of its deck, a height ``top`` above the
ground, and turns with the heading and the pitch (positive nose down),
:math:`R = R_z(\\psi) R_y(\\theta)`; the reduced models take the rider's torques about that
origin (a simplification: the real platforms pitch about their axles, a few centimetres
lower). Each class is data plus the few functions the ride problem calls.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.boards.canonical import BoardState, canonical_board_states
from ridempc.boards.hovershoes.parameters import HovershoesParameters, HovershoesReducedParameters
from ridempc.boards.hovershoes.reduced import STATE_NAMES as SHOE_STATE
from ridempc.boards.hovershoes.reduced import STATE_QUANTITIES as SHOE_QUANTITIES
from ridempc.boards.hovershoes.reduced import contact_torques, shoe_dynamics
from ridempc.boards.segway.parameters import SegwayParameters, SegwayReducedParameters
from ridempc.boards.segway.reduced import STATE as SEGWAY_STATE
from ridempc.boards.segway.reduced import STATE_QUANTITIES as SEGWAY_QUANTITIES
from ridempc.boards.segway.reduced import segway_dynamics
from ridempc.errors import ConfigError
from ridempc.trajopt.rotations import rotation_z, stack3x3

__all__ = [
    "SIDES",
    "HovershoesBoard",
    "SegwayBoard",
    "WheeledBoard",
    "platform_pushes",
    "wheeled_board",
]

SIDES: tuple[str, ...] = ("left", "right")  # the Hovershoes' shoes, in platform order

Array = NDArray[np.float64]


def _rotation_y(angle: Any) -> Any:
    c, s = ca.cos(angle), ca.sin(angle)
    return stack3x3([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]], ca)


@dataclass(frozen=True)
class _Common:
    """Figures both kinds share.

    Attributes:
        name: Board name.
        top: Deck top above the ground [m].
        speed_limit: Largest forward speed [m/s].
        pitch_limit: Largest platform pitch [rad].
        state_names: Names of the board's states.
        input_names: Names of the board's own inputs (besides the rider's forces).
        input_bound: Bound on each of those inputs (symmetric).
        yaw_torque_limit: Largest rider yaw torque on one platform [N m] (inf: none).
    """

    name: str
    top: float
    speed_limit: float
    pitch_limit: float
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    input_bound: Array
    yaw_torque_limit: float


@dataclass(frozen=True)
class HovershoesBoard(_Common):
    """Two Hovershoes; platform 0 is the left shoe (+y), 1 the right.

    **The rider's push.** Eq. (8), :math:`m \\dot v = c_4 \\theta`, was identified with a
    dead weight riding along, so :math:`m` [kg] is the shoe's and its load's mass: it holds
    while the load keeps the shoe's speed. A rider may push its shoe instead; on the bare
    shoe (mass :math:`m_s`, from the board's description) the firmware's drive
    :math:`c_4 \\theta` and the rider's push :math:`P` [N] (the rider's force on the shoe
    along its heading) give

    .. math:: m_s \\dot v = c_4 \\theta + P,

    which is eq. (8) again when the load follows the shoe, :math:`P = -(m - m_s) \\dot v`.
    Without it the MPC saw a free horizontal force: a 15 N push accelerates a 2.7 kg shoe at
    5.5 m/s^2, which the model had at zero (measured on the stand-still ride, where every
    plan then swung the shoes back and forth).

    Attributes:
        reduced: The identified eq. (4)-(8).
        shoe_mass: :math:`m_s` [kg], one shoe without its load.
    """

    reduced: HovershoesReducedParameters
    shoe_mass: float

    @property
    def n_platforms(self) -> int:
        return len(SIDES)

    def platform_prefixes(self) -> tuple[str, ...]:
        """Each shoe's prefix of its state names, in platform order (left, right)."""
        return tuple(f"{side}_" for side in SIDES)

    def board_states(self) -> dict[str, BoardState]:
        """Each state name as its canonical quantity, per shoe (left, right)."""
        return canonical_board_states(self.platform_prefixes(), SHOE_QUANTITIES)

    def platform_state(self, xb: Any, platform: int) -> Any:
        return xb[7 * platform : 7 * platform + 7]

    def pose(self, xb: Any, platform: int) -> tuple[Any, Any]:
        """Rotation and origin (deck top centre) of one shoe."""
        s = self.platform_state(xb, platform)
        rotation = rotation_z(s[2], ca) @ _rotation_y(s[3])
        return rotation, ca.vertcat(s[0], s[1], self.top)

    def speed(self, xb: Any, platform: int) -> Any:
        return self.platform_state(xb, platform)[6]

    def heading(self, xb: Any, platform: int) -> Any:
        return self.platform_state(xb, platform)[2]

    def heading_index(self, platform: int) -> int:
        """Index of a platform's heading in the board state."""
        return 7 * platform + 2

    def pitch(self, xb: Any, platform: int) -> Any:
        return self.platform_state(xb, platform)[3]

    def pitch_rate(self, xb: Any, platform: int) -> Any:
        return self.platform_state(xb, platform)[4]

    def rates(self, xb: Any, torques: list[tuple[Any, Any]], extra: Any, pushes: list[Any]) -> Any:
        """Eq. (4)-(7) per shoe under the rider's torques :math:`(u_\\theta, u_\\psi)`, and
        eq. (8) with the rider's push (the class docstring)."""
        out = []
        for i in range(2):
            state = self.platform_state(xb, i)
            rates = list(shoe_dynamics(state, torques[i], self.reduced, ca))
            rates[6] = (self.reduced.c4 * state[3] + pushes[i]) / self.shoe_mass
            out.append(ca.vertcat(*rates))
        return ca.vertcat(*out)

    def steady(self, speed: float, origins: Array) -> Array:
        """Both shoes rolling straight at ``speed`` with no pitch, at ``origins`` (2 x 2)."""
        state = []
        for x, y in origins:
            state += [x, y, 0.0, 0.0, 0.0, 0.0, speed]
        return np.array(state)


@dataclass(frozen=True)
class SegwayBoard(_Common):
    """A Segway; the knee-bar angle is an input of the trajectory."""

    reduced: SegwayReducedParameters

    @property
    def n_platforms(self) -> int:
        return 1

    def platform_prefixes(self) -> tuple[str, ...]:
        """The platform's prefix of its state names (the board's name)."""
        return (f"{self.name}_",)

    def board_states(self) -> dict[str, BoardState]:
        """Each state name as its canonical quantity (one platform)."""
        return canonical_board_states(self.platform_prefixes(), SEGWAY_QUANTITIES)

    def pose(self, xb: Any, platform: int) -> tuple[Any, Any]:
        rotation = rotation_z(xb[2], ca) @ _rotation_y(xb[3])
        return rotation, ca.vertcat(xb[0], xb[1], self.top)

    def speed(self, xb: Any, platform: int) -> Any:
        return xb[5]

    def heading(self, xb: Any, platform: int) -> Any:
        return xb[2]

    def heading_index(self, platform: int) -> int:
        """Index of the heading in the board state."""
        return 2

    def pitch(self, xb: Any, platform: int) -> Any:
        return xb[3]

    def pitch_rate(self, xb: Any, platform: int) -> Any:
        return xb[4]

    def rates(self, xb: Any, torques: list[tuple[Any, Any]], extra: Any, pushes: list[Any]) -> Any:
        """Eq. (4'), (5'), (8') under the rider's pitch torque and the knee-bar angle (the
        rider's yaw torque goes into the wheels, not into the model; so does its push: the
        Segway's 12.8 kg, held by its drive, is left as identified with its load)."""
        return ca.vertcat(*segway_dynamics(xb, (torques[0][0], extra[0]), self.reduced, ca))

    def steady(self, speed: float, origins: Array) -> Array:
        """Rolling straight at ``speed``: the pitch where eq. (4') and (8') balance with no
        pitch rate, :math:`u_\\theta = c_1\\theta + c_3 v` and
        :math:`c_4\\theta + c_5 v - c_7 u_\\theta = 0`."""
        p = self.reduced
        pitch = -(p.c5 - p.c7 * p.c3) * speed / (p.c4 - p.c7 * p.c1)
        ((x, y),) = origins
        return np.array([x, y, 0.0, pitch, 0.0, speed, 0.0])

    def steady_torque(self, speed: float) -> float:
        """Rider pitch torque that holds :meth:`steady` [N m]."""
        p = self.reduced
        pitch = self.steady(speed, np.zeros((1, 2)))[3]
        return float(p.c1 * pitch + p.c3 * speed)


WheeledBoard = HovershoesBoard | SegwayBoard


def wheeled_board(board: Board, pitch_limit: float = 0.25) -> WheeledBoard:
    """The optimisation's view of the Hovershoes or the Segway.

    Raises:
        ConfigError: Another kind of board, or no identified reduced model.
    """
    params = board.params
    if getattr(params, "reduced", None) is None:
        raise ConfigError(
            f"{board.folder / 'board.toml'}: no [reduced] table; run `ridempc board identify`"
        )
    features = board.kind.features
    if "shoes" in features:
        params = cast(HovershoesParameters, params)
        assert params.reduced is not None
        names = tuple(f"{side}_{n}" for side in SIDES for n in SHOE_STATE)
        return HovershoesBoard(
            name=board.name,
            top=params.platform_height,
            speed_limit=params.speed_limit,
            pitch_limit=pitch_limit,
            state_names=names,
            input_names=(),
            input_bound=np.zeros(0),
            # Tyre breakaway: the rims creep linearly (the model's c3) up to about 4 N m.
            yaw_torque_limit=4.0,
            reduced=params.reduced,
            shoe_mass=board.mass / 2.0,
        )
    if "knee_bar" in features:
        params = cast(SegwayParameters, params)
        assert params.reduced is not None
        return SegwayBoard(
            name=board.name,
            top=params.platform_height,
            speed_limit=params.top_speed,
            pitch_limit=pitch_limit,
            state_names=tuple(f"{board.name}_{n}" for n in SEGWAY_STATE),
            input_names=("knee_bar",),
            input_bound=np.array([np.radians(params.knee_bar_range)]),
            yaw_torque_limit=float("inf"),
            reduced=params.reduced,
        )
    raise ConfigError(f"board '{board.name}' is not a Hovershoes pair or a Segway")


def platform_torques(
    board: WheeledBoard, xb: Any, forces: list[Any], points: list[Any], platform_of: list[int]
) -> list[tuple[Any, Any]]:
    """Eq. (9) per platform: the rider's :math:`(u_\\theta, u_\\psi)` from the contact forces
    on the rider (world) at the contact points (world)."""
    torques = []
    for i in range(board.n_platforms):
        rotation, origin = board.pose(xb, i)
        mine = [k for k, p in enumerate(platform_of) if p == i]
        positions = [rotation.T @ (points[k] - origin) for k in mine]
        local = [rotation.T @ forces[k] for k in mine]
        torques.append(contact_torques(positions, local))
    return torques


def platform_pushes(
    board: WheeledBoard, xb: Any, forces: list[Any], platform_of: list[int]
) -> list[Any]:
    """Per platform, the rider's push along its heading [N]: :math:`P = -\\sum_k
    (R^\\top F_k)_x` over its contacts, :math:`F_k` the contact forces on the rider (world)."""
    pushes = []
    for i in range(board.n_platforms):
        rotation, _ = board.pose(xb, i)
        mine = [k for k, p in enumerate(platform_of) if p == i]
        push = ca.SX(0.0) if not mine else -sum((rotation.T @ forces[k])[0] for k in mine)
        pushes.append(push)
    return pushes
