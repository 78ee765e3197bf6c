"""What the MPC needs from a robot-board pair besides its library: surfaces, limits.

The dynamics come from the pair's trajectory optimisation
(:func:`ridempc.trajopt.pairs.load_pair`, ``Pair.rates``); what the library entries do not
carry is, per contact, the rotation of the board surface it stands on (for the friction
pyramids) and the limits of the inputs that are not forces (joint speeds, the Segway's knee
bar). Each pair's builder reads them from the same models the optimisation used, so the
MPC's constraints are the library's. The pair's settings and stages come from its pair file
(:mod:`ridempc.pair_description`): a new pair is a new file.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from functools import cache, lru_cache, partial
from types import MappingProxyType
from typing import Any, NamedTuple, cast

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.boards import load_board
from ridempc.boards.canonical import BoardState
from ridempc.boards.hovershoes.parameters import HovershoesParameters
from ridempc.errors import ConfigError
from ridempc.mpc.buffered import BufferedFunction
from ridempc.mpc.codegen import compiled
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.settle import settle_over_feet
from ridempc.pair_description import (
    PairDescription,
    load_pair_description,
    pair_description_names,
)
from ridempc.trajopt.mirror import Symmetry, symmetry_or_none
from ridempc.trajopt.pairs import Pair, load_pair
from ridempc.trajopt.ride_pair import ride_models
from ridempc.trajopt.ride_problem import ride_layout
from ridempc.trajopt.rigid_body import GRAVITY
from ridempc.trajopt.skate_pair import skate_models
from ridempc.trajopt.skateboard import BOARD_STATE, deck_frame

__all__ = [
    "MpcPair",
    "check_library_names",
    "load_mpc_pair",
    "mpc_pair_names",
    "surface_rotations",
]

Array = NDArray[np.float64]


def mpc_pair_names() -> tuple[str, ...]:
    """The pairs the MPC can ride: those with a pair file (``pairs/``)."""
    return pair_description_names()


class MpcPair(NamedTuple):
    """A pair as the MPC sees it, built from its pair file (``pairs/<robot>-<board>.toml``,
    :mod:`ridempc.pair_description`; the measurements behind each setting:
    ``docs/tuning.md``, "Pair files").

    Attributes:
        pair: The trajectory-optimisation pair (its ``rates`` rebuild the dynamics).
        contacts: Contact names, in the order of the library's force inputs.
        surfaces: CasADi function :math:`x \\mapsto [R_1 \\dots R_{n_c}]` (3 x 3 n_c): per
            contact, the rotation (world from surface) of the deck or platform it stands
            on, in the library's contact order.
        input_limits: Symmetric bound of each input (nu), inf where the friction pyramids
            bound it (the forces) [rad/s], [rad].
        max_force: Largest normal force of one contact, :math:`f_{max}` [N] (the library's).
        weight: The robot's weight [N] (forces are weighed in units of its share per contact).
        description: The pair file it was built from (its WBC settings and stages).
        base: The robot's base body, whose Z-Y-X angles the states carry (``<base>_roll``).
        board_states: Per board state name, its platform and canonical quantity
            (:mod:`ridempc.boards.canonical`), from the board's reduced model.
        platform_prefixes: Each platform's prefix of its state names, in platform order.
        pyramid: The friction pyramid's shape in the MPC and the whole-body QP
            (:data:`ridempc.friction.SHAPES`): ``diamond`` where line feet must twist a
            platform to turn it, ``box`` elsewhere.
        tipping: Per platform that tips over its wheel's tread (the ``tipping`` stage), its
            contacts and :math:`k = w / 2h`, half the tread over the deck's height [-]
            (:func:`~ridempc.mpc.friction.friction_pyramids`).
        force_time_constant: Time constant of the low-pass on the forces the whole-body
            QP is given [s] (the ``force_filter`` stage,
            :class:`~ridempc.mpc.force_filter.ForceFilter`), or None to pass the plan's
            first input as it is.
        terminal_factor: The MPC's terminal weight over its stage weight,
            :math:`Q_N = ` this :math:`\\times Q` [-], standing in for the cost beyond the
            horizon.
        start_speed: An ``accelerate`` from rest starts where its reference first reaches
            this speed [m/s] (:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.phase_start`),
            skipping the library's steady start.
        roll_observer: :math:`\\beta` of the deck's disturbance-torque estimate
            (the ``roll_observer`` stage, :class:`~ridempc.mpc.roll_observer.RollObserver`)
            [-], or None for none.
        swing_force_step: While a foot swings and no contact changes, the tolerance of each
            deck force's change from one solve's first input to the next [N] (the
            ``swing_force_hold`` stage, :func:`~ridempc.mpc.input_rate.hold_first_input`,
            :math:`S = 1/\\sigma^2`), or None for none.
        push_tolerances: Over a push-off, the accepted deviation of these states, by
            name, in their units (the ``push_weights`` stage,
            :mod:`~ridempc.mpc.push_weights`); empty for none.
        push_max_target: The largest push-off target [m/s] the ``push_tolerances`` apply to.
        stance_roll: :math:`s` of the deck roll's stance limit (the ``stance`` stage,
            :class:`~ridempc.mpc.stance.StanceLimit`), the estimated centre-of-mass offset
            per radian of deck roll [m/rad], or None for no limit.
        speed_preview: Where the ride's commands are planned ahead (the rider's
            ``command_preview``), the manoeuvre follows the speed command planned for the
            end of the MPC's horizon, as the yaw rate and the deck roll are read over it:
            the rider leans into a planned speed step before it comes.
        plan_latency: Control ticks (2 ms each) from the MPC's tick to the tick its plan
            takes over (:class:`~ridempc.mpc.rider.MpcRider`), the plan solved from the
            state predicted there (:mod:`~ridempc.mpc.delay`): with 1, OSQP iterates in a
            thread beside the control loop, from 2 the problem is built and solved in a
            process of its own, as on the robots; with 0 the loop waits for it in the tick.
        predict_start: Whether a plan taken up ``plan_latency`` ticks late is solved from
            the state predicted at its take-up (:mod:`~ridempc.mpc.delay`), else from the
            tick's, its time shifted.
        roll_lead: How far ahead of each horizon node the commanded deck roll is read [s]
            (the ``roll_lead`` stage): the closed loop's deck follows the plan's roll late
            (the MPC's steps, the whole-body QP's tracking, the trucks).
        settle: What the reference does after its end besides riding on (the ``settle``
            stage, :mod:`~ridempc.mpc.settle`: the robot settles back over its feet), or
            None for nothing.
        symmetry: The robot's left-right symmetry, whose mirror images of the library's
            re-pushes push from the other side (:mod:`~ridempc.mpc.push_side`), or None.
    """

    pair: Pair
    contacts: tuple[str, ...]
    surfaces: ca.Function
    input_limits: Array
    max_force: float
    weight: float
    description: PairDescription
    base: str
    board_states: Mapping[str, BoardState]
    platform_prefixes: tuple[str, ...]
    pyramid: str = "box"
    tipping: tuple[tuple[tuple[int, ...], float], ...] = ()
    force_time_constant: float | None = None
    terminal_factor: float = 10.0
    start_speed: float = 0.0
    roll_observer: float | None = None
    swing_force_step: float | None = None
    push_tolerances: Mapping[str, float] = MappingProxyType({})
    push_max_target: float = math.inf
    stance_roll: float | None = None
    speed_preview: bool = False
    plan_latency: int = 0
    predict_start: bool = True
    roll_lead: float = 0.0
    settle: Callable[[MotionReference], MotionReference] | None = None
    symmetry: Symmetry | None = None


def surface_rotations(pair: MpcPair, x0: Array) -> Array:
    """Per contact, the surface rotation at the state ``x0``, n_c x 3 x 3 (the pair's
    ``surfaces`` compiled and called through NumPy buffers, :func:`_buffered`)."""
    (stacked,) = _buffered(pair.surfaces)(np.asarray(x0, dtype=float))
    return stacked.reshape(3, -1, 3).transpose(1, 0, 2)


@lru_cache(maxsize=8)
def _buffered(function: ca.Function) -> BufferedFunction:
    """``function`` compiled (:func:`~ridempc.mpc.codegen.compiled`) and buffered, once
    per function."""
    return BufferedFunction(compiled(function))


def _settings(description: PairDescription) -> dict[str, Any]:
    """The MpcPair fields the pair file sets: its MPC section and its stages."""
    mpc, stages = description.mpc, description.stages
    push = stages.push_weights
    return {
        "pyramid": mpc.pyramid,
        "force_time_constant": (
            stages.force_filter.time_constant if stages.force_filter is not None else None
        ),
        "terminal_factor": mpc.terminal_factor,
        "start_speed": mpc.start_speed,
        "roll_observer": stages.roll_observer.gain if stages.roll_observer is not None else None,
        "swing_force_step": (
            stages.swing_force_hold.force_step if stages.swing_force_hold is not None else None
        ),
        "push_tolerances": MappingProxyType(dict(push.tolerances) if push is not None else {}),
        "push_max_target": push.max_target if push is not None else math.inf,
        "stance_roll": stages.stance.roll_offset if stages.stance is not None else None,
        "speed_preview": mpc.speed_preview,
        "plan_latency": mpc.plan_latency,
        "predict_start": mpc.predict_start,
        "roll_lead": stages.roll_lead.lead if stages.roll_lead is not None else 0.0,
        "description": description,
    }


def _skate(description: PairDescription) -> MpcPair:
    """A quadruped on a deck: every contact on the deck's surface; each force component
    bounded at twice the weight (the library's bound, skate_problem)."""
    robot, board = skate_models(description.robot, description.board)
    nf, nr = robot.n_feet, 12 + robot.n_joints
    x = ca.SX.sym("x", nr + len(BOARD_STATE))
    rotation, _ = deck_frame(board, x[nr:])
    surfaces = ca.Function("contact_surfaces", [x], [ca.horzcat(*[rotation] * nf)])
    limits = np.concatenate([np.full(3 * nf, np.inf), robot.speed_limit])
    pair = load_pair(description.robot, description.board)
    weight = robot.mass * GRAVITY
    settle = description.stages.settle
    return MpcPair(
        pair,
        robot.feet,
        surfaces,
        limits,
        2.0 * weight,
        weight,
        base=robot.base,
        board_states=MappingProxyType(board.board_states()),
        platform_prefixes=board.platform_prefixes(),
        settle=(
            partial(
                settle_over_feet,
                robot=robot,
                duration=settle.duration,
                board_states=board.board_states(),
            )
            if settle is not None
            else None
        ),
        symmetry=symmetry_or_none(robot),
        **_settings(description),
    )


def _ride(description: PairDescription) -> MpcPair:
    """A biped on a wheeled board: each contact on its platform's surface; one contact may
    carry the whole weight (the library's bound, ride_problem)."""
    robot, board = description.robot, description.board
    rider, wheeled = ride_models(robot, board)
    layout = ride_layout(rider, wheeled)
    x = ca.SX.sym("x", 12 + len(wheeled.state_names))
    rotations = [wheeled.pose(x[12:], platform)[0] for platform in layout["platform_of"]]
    surfaces = ca.Function("contact_surfaces", [x], [ca.horzcat(*rotations)])
    limits = np.concatenate([np.full(3 * rider.n_contacts, np.inf), wheeled.input_bound])
    pair = load_pair(robot, board)
    weight = rider.body.mass * GRAVITY
    tipping: tuple[tuple[tuple[int, ...], float], ...] = ()
    loaded = load_board(board)
    if description.stages.tipping is not None:  # a board with shoes (the stage's check)
        shoes = cast(HovershoesParameters, loaded.params if loaded is not None else None)
        ratio = 0.5 * shoes.wheel_width / shoes.platform_height
        platform_of = layout["platform_of"]
        tipping = tuple(
            (tuple(k for k, p in enumerate(platform_of) if p == i), ratio)
            for i in range(wheeled.n_platforms)
        )
    return MpcPair(
        pair,
        rider.contacts,
        surfaces,
        limits,
        weight,
        weight,
        base=rider.body.base,
        board_states=MappingProxyType(wheeled.board_states()),
        platform_prefixes=wheeled.platform_prefixes(),
        tipping=tipping,
        **_settings(description),
    )


# A pair file's ``trajopt.problem`` -> how the MPC reads its surfaces and limits.
_BUILDERS: dict[str, Callable[[PairDescription], MpcPair]] = {"ride": _ride, "skate": _skate}


@cache
def load_mpc_pair(robot: str, board: str) -> MpcPair:
    """The MPC's view of a pair (built once per process from its pair file).

    Raises:
        UnknownNameError: No pair file for that pair; the message lists those described.
        ConfigError: The pair file is malformed or does not fit its robot and board.
    """
    description = load_pair_description(robot, board)
    return _BUILDERS[description.trajopt.problem](description)


def check_library_names(description: PairDescription, reference: MotionReference) -> None:
    """The state and input names a pair file gives are its library's.

    Raises:
        ConfigError: A push tolerance names no state, or an unrealised input no input, of
            the library's ``reference``; the message names the pair file and the field.
    """
    shown = f"pairs/{description.name}.toml"
    push = description.stages.push_weights
    for name in push.tolerances if push is not None else {}:
        if name not in reference.state_names:
            raise ConfigError(
                f"{shown}: field 'stages.push_weights.tolerances.{name}': no such state in "
                f"the library; allowed: {', '.join(reference.state_names)}"
            )
    for name in description.mpc.unrealised_inputs:
        if name not in reference.input_names:
            raise ConfigError(
                f"{shown}: field 'mpc.unrealised_inputs': '{name}' is no input of the "
                f"library; allowed: {', '.join(reference.input_names)}"
            )
