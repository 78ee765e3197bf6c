"""The skateboard side of the optimisation: deck frame, eq. (7), (10) and the Dubins kinematics.

Board state :math:`x_B = (x, y, \\psi_z, v, \\varphi, \\dot\\varphi)`: position of the deck's
top centre :math:`C_B` on the ground plane [m], heading [rad], forward speed along the deck
[m/s] (no side slip, :math:`v^B_{B_y} = 0`, eq. 13), deck roll [rad] and roll rate [rad/s].
The deck frame :math:`R_B = R_z(\\psi_z) R_x(\\varphi)` has its origin at the deck's top
centre, a height ``deck_height`` above the ground.

.. math::

    \\dot v = \\frac{1}{m_B}\\Big(-S_x R_B^\\top \\sum_{i \\in deck} f_i
              - \\tanh(k v)\\, f_{fri} - c_v v\\Big) \\quad (10) \\\\
    I_{Bx}\\ddot\\varphi = -\\big(R_B^\\top \\sum_{i \\in deck} r_{B_i} \\times f_i\\big)_x
              - K_B \\varphi - B_B \\dot\\varphi \\quad (6), (7) \\\\
    \\dot x = v\\cos\\psi_z, \\; \\dot y = v\\sin\\psi_z, \\;
    \\dot\\psi_z = -v \\sin\\varphi / K_{board} \\quad (14)

:math:`f_i` are the forces on the robot (so :math:`-f_i` on the deck) and :math:`r_{B_i}`
the contact points from the deck's top centre. The Coulomb rolling resistance
:math:`f_{fri}` [N] is the board's four wheel-bearing friction torques over the wheel radius,
smoothed by :math:`\\tanh(k v)` as the paper's eq. (10) does; :math:`c_v` [N s/m] is the
bearings' viscous part. The roll and steering rows reuse the board's identified reduced
model (:mod:`ridempc.boards.skateboard.reduced`) with ``xp = casadi``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import casadi as ca

from ridempc.boards.board import Board
from ridempc.boards.canonical import BoardState, canonical_board_states
from ridempc.boards.skateboard.parameters import SkateboardParameters, SkateboardReducedParameters
from ridempc.boards.skateboard.reduced import dubins_rates, roll_acceleration
from ridempc.errors import ConfigError
from ridempc.trajopt.rotations import rotation_x, rotation_z

__all__ = [
    "BOARD_STATE",
    "DECK_QUANTITIES",
    "SkateboardModel",
    "deck_frame",
    "skateboard_model",
    "skateboard_rates",
]

BOARD_STATE: tuple[str, ...] = (
    "board_x",
    "board_y",
    "board_yaw",
    "board_v",
    "board_roll",
    "board_roll_rate",
)
DECK_PREFIX = "board_"  # the deck's states' prefix in BOARD_STATE
# What each deck state is, by its canonical name (ridempc.boards.canonical).
DECK_QUANTITIES: dict[str, str] = {
    "x": "x",
    "y": "y",
    "yaw": "heading",
    "v": "speed",
    "roll": "roll",
    "roll_rate": "roll_rate",
}


@dataclass(frozen=True)
class SkateboardModel:
    """Figures of the board the optimisation needs.

    Attributes:
        mass: Translating mass :math:`m_B` [kg]: the board's mass plus its wheels' spin
            inertia reflected to the ground (:math:`4 I_w / r^2 = 2 m_w`).
        deck_height: Deck top above the ground [m].
        half_length: Half the deck length [m].
        half_width: Half the deck width [m].
        roll_limit: Largest deck roll [rad].
        friction_force: Coulomb rolling resistance :math:`f_{fri}` [N].
        viscous_drag: Viscous rolling resistance :math:`c_v` [N s / m].
        friction_sharpness: :math:`k` of eq. (10) [s / m].
        reduced: The identified roll and steering model.
        name: The board's name (its description's).
    """

    mass: float
    deck_height: float
    half_length: float
    half_width: float
    roll_limit: float
    friction_force: float
    viscous_drag: float
    friction_sharpness: float
    reduced: SkateboardReducedParameters
    name: str

    def platform_prefixes(self) -> tuple[str, ...]:
        """The deck's prefix of its state names."""
        return (DECK_PREFIX,)

    def board_states(self) -> dict[str, BoardState]:
        """Each of :data:`BOARD_STATE` as its canonical quantity (one platform, the deck)."""
        return canonical_board_states(self.platform_prefixes(), DECK_QUANTITIES)


def skateboard_model(board: Board, friction_sharpness: float = 20.0) -> SkateboardModel:
    """The optimisation's view of a skateboard.

    Raises:
        ConfigError: The board is not a skateboard or has no identified reduced model.
    """
    if "deck_roll" not in board.kind.features:
        raise ConfigError(f"board '{board.name}' is not a skateboard (no rolling deck)")
    params = cast(SkateboardParameters, board.params)
    if params.reduced is None:
        raise ConfigError(
            f"{board.folder / 'board.toml'}: no [reduced] table; run `ridempc board identify`"
        )
    r = params.wheel_radius
    return SkateboardModel(
        mass=board.mass + 2.0 * params.wheel_mass,
        deck_height=params.height,
        half_length=params.deck_length / 2.0,
        half_width=params.deck_width / 2.0,
        roll_limit=params.roll_limit,
        friction_force=4.0 * params.wheel_friction_torque / r,
        viscous_drag=4.0 * params.wheel_damping / r**2,
        friction_sharpness=friction_sharpness,
        reduced=params.reduced,
        name=board.name,
    )


def deck_frame(board: SkateboardModel, state: Any) -> tuple[Any, Any]:
    """Deck rotation :math:`R_B = R_z(\\psi_z) R_x(\\varphi)` and origin (top centre) [m]."""
    rotation = rotation_z(state[2], ca) @ rotation_x(state[4], ca)
    origin = ca.vertcat(state[0], state[1], board.deck_height)
    return rotation, origin


def skateboard_rates(
    board: SkateboardModel, state: Any, forces: list[Any], points: list[Any]
) -> Any:
    """:math:`\\dot x_B` under the robot's deck forces, eq. (6), (7), (10), (14) (CasADi).

    Args:
        board: The board.
        state: :math:`x_B` (see :data:`BOARD_STATE`).
        forces: Forces on the robot at its deck contacts, world frame [N] (zero for a foot
            that is not on the deck).
        points: World positions of those contacts [m].
    """
    rotation, origin = deck_frame(board, state)
    push = ca.DM.zeros(3)
    moment = ca.DM.zeros(3)
    for f, p in zip(forces, points, strict=True):
        push = push + f
        moment = moment + ca.cross(p - origin, f)
    speed = state[3]
    drag = ca.tanh(board.friction_sharpness * speed) * board.friction_force
    drag = drag + board.viscous_drag * speed
    speed_rate = (-(rotation.T @ push)[0] - drag) / board.mass  # eq. (10)
    roll_torque = -(rotation.T @ moment)[0]
    reduced = board.reduced
    roll_rate = roll_acceleration(
        state[4],
        state[5],
        roll_torque,
        reduced.roll_inertia,
        reduced.roll_stiffness,
        reduced.roll_damping,
    )
    x_rate, y_rate, yaw_rate = dubins_rates(state[2], speed, state[4], reduced.steer_gain, ca)
    return ca.vertcat(x_rate, y_rate, yaw_rate, speed_rate, state[5], roll_rate)
