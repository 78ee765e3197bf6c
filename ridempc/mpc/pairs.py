"""What the MPC needs from a robot-board pair besides its library: surfaces, limits.

The dynamics come from the pair's trajectory-optimisation module
(:data:`ridempc.trajopt.pairs.PAIRS`, ``Pair.rates``); what the library entries do not
carry is, per contact, the rotation of the board surface it stands on (for the friction
pyramids) and the limits of the inputs that are not forces (joint speeds, the Segway's knee
bar). Each pair's builder reads them from the same models the optimisation used, so the
MPC's constraints are the library's. The table :data:`MPC_PAIRS` maps
``<robot>-<board>`` to its builder: a new pair is a builder and one line.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from functools import cache, lru_cache, partial
from types import MappingProxyType
from typing import NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.boards import load_board
from ridempc.boards.hovershoes.parameters import HovershoesParameters
from ridempc.errors import UnknownNameError
from ridempc.mpc.buffered import BufferedFunction
from ridempc.mpc.codegen import compiled
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.settle import settle_over_feet
from ridempc.trajopt.pairs import Pair, load_pair
from ridempc.trajopt.ride_pair import ride_models
from ridempc.trajopt.ride_problem import ride_layout
from ridempc.trajopt.rigid_body import GRAVITY
from ridempc.trajopt.skate_pair import skate_models
from ridempc.trajopt.skateboard import BOARD_STATE, deck_frame

__all__ = ["MPC_PAIRS", "MpcPair", "load_mpc_pair", "surface_rotations"]

Array = NDArray[np.float64]
SETTLE_TIME: float = 1.5  # [s] the skateboard's settle over its feet after a push-off


class MpcPair(NamedTuple):
    """A pair as the MPC sees it.

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
        pyramid: The friction pyramid's shape in the MPC and the whole-body QP
            (:data:`ridempc.friction.SHAPES`): ``diamond`` on the Hovershoes, whose shoes
            Cassie's line feet must twist to turn (in the ``box`` her circle fell at 8.17 s,
            3 s into the turn; in the diamond at 16.41 s, and yaw-steps held 0.5 rad/s for
            9 s instead of 1; straight riding within 0.003 m/s of the box's RMSE), ``box``
            elsewhere (the dog's push-off-0.7 reached 0.629 m/s in the diamond, 0.667 in
            the box, and push-off-0.5 fell at 4.14 s in the diamond: measured).
        tipping: Per platform that tips over its wheel's tread (a Hovershoe), its contacts
            and :math:`k = w / 2h`, half the tread over the deck's height [-] (with them
            the circle rode to 24.42 s of its 25, seed 0)
            (:func:`~ridempc.mpc.friction.friction_pyramids`).
        force_time_constant: Time constant of the low-pass on the forces the whole-body
            QP is given [s] (:class:`~ridempc.mpc.force_filter.ForceFilter`), or None to
            pass the plan's first input as it is: 0.042 s on the Hovershoes, whose toes and
            shoes rang at 7-9 Hz on the unfiltered forces (at 0.084 s, yaw-steps seeds
            0/1/2/3: yaw-rate RMSE 0.0617/0.0697/0.0626/fell at 21.87 s -> 0.0431/0.0431/
            0.0427/0.0414 rad/s; but the circle, seeds 0/1, fell at 17.04/17.50 s instead of
            22.69/18.81). From 0.084 to 0.042 s the filter lags less behind the lean into a
            speed step: velocity-steps seeds 0-3, velocity RMSE 0.110/0.107/0.105/0.108 ->
            0.1046/0.1041/0.1032/0.1050 m/s; seed 0 unless stated, yaw-steps yaw-rate RMSE
            0.0441 -> 0.0437 rad/s (seeds 1, 3: 0.0448 -> 0.0435, 0.0428 -> 0.0416), the
            circle's 0.0261 -> 0.0205 (seed 1: 0.0284 -> 0.0230; foot-spacing RMSE 0.024 ->
            0.027 m), push's velocity RMSE 0.0470 -> 0.0464 m/s, offset-start's 0.0108 ->
            0.0126 (yaw-rate 0.0394 -> 0.0221), wave's 0.0070 -> 0.0071; all ride to their
            ends. None on the Segway, where it quietened the toes too but velocity-steps
            fell at 15.38 s (seed 0; circle yaw-rate RMSE 0.063 -> 0.071), and on the
            skateboard, whose dog lifts its feet.
        terminal_factor: The MPC's terminal weight over its stage weight,
            :math:`Q_N = ` this :math:`\\times Q` [-], standing in for the cost beyond the
            0.4 s horizon: 30 on the Hovershoes, 10 elsewhere. At 10 the Hovershoes' plans
            let the rider roll back at rest, each ending 0.1 m behind its reference and
            0.07 m/s slower, and the rides settled 0.03-0.04 m/s short of each commanded
            speed. From 10 to 30 (seed 0): stand-still's velocity RMSE 0.0566 -> 0.0128
            m/s, offset-start's 0.0548 -> 0.0110, push's 0.0601 -> 0.0471, wave's 0.0413 ->
            0.0067, velocity-steps' 0.1425 -> 0.1228 (seed 1: 0.1417 -> 0.1190), yaw-steps'
            yaw-rate RMSE 0.0431 -> 0.0433 rad/s, and the circle, which fell at 17.04 s,
            rode to its end, its shoes drifting apart (0.42 -> 0.57 m, seed 1) until their
            headings were read off their travel (:mod:`~ridempc.mpc.shoe_heading`). At 20
            velocity-steps gave 0.1237; at 50 and 100 the plans pitched the shoes so hard
            for the step from 1.0 to 1.5 m/s that they ran from under the rider (fell at
            23.83 and 13.98 s).
        start_speed: An ``accelerate`` from rest starts where its reference first reaches
            this speed [m/s] (:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.phase_start`),
            skipping the library's steady start and the slowest of its lean-in: 0.06 on the
            Hovershoes (velocity-steps seed 0, velocity RMSE 0.1228 at 0, 0.1126 at 0.03,
            0.1102 at 0.06, 0.1085 at 0.1; seed 1 0.1190 -> 0.1070 at 0.06), 0 elsewhere
            (the dog's push-offs start with the board still).
        roll_observer: :math:`\\beta` of the deck's disturbance-torque estimate
            (:class:`~ridempc.mpc.roll_observer.RollObserver`) [-], or None for none: 0.3 on
            the skateboard, None elsewhere (no deck roll).
        swing_force_step: While a foot swings and no contact changes, the tolerance of each
            deck force's change from one solve's first input to the next [N]
            (:func:`~ridempc.mpc.input_rate.hold_first_input`, :math:`S = 1/\\sigma^2`), or
            None for none: 10 N on the skateboard, where push-off-1.0's light front foot lost
            the deck in the last stroke's swing and the ride fell (seeds 0/1 ride through
            with it; at 10 N in every phase push-off-0.3 seed 1 and push-off-1.0 seed 1
            fell, at 5 N push-off-1.0 fell at 1.7 s), None elsewhere.
        push_tolerances: Over a push-off, the accepted deviation of these states, by
            name, in their units (:mod:`~ridempc.mpc.push_weights`): on the skateboard the
            CoM's speed ``vx`` within 0.0125 m/s and the board's ``board_v`` within
            0.05 m/s, which brought push-off-0.3's final speed on seeds 0-3 from
            0.281/0.276/0.332/0.267 to 0.301/0.298/0.318/0.297 m/s and push-off-0.5's from
            0.488/0.480/0.479/0.487 to 0.499/0.504/0.503/0.494; empty elsewhere (no pushes).
        push_max_target: The largest push-off target [m/s] the ``push_tolerances`` apply
            to: 0.7 on the skateboard (push-off-1.0 falls in its last stroke with them).
        stance_roll: :math:`s` of the deck roll's stance limit
            (:class:`~ridempc.mpc.stance.StanceLimit`), the estimated centre-of-mass
            offset per radian of deck roll [m/rad], or None for no limit: 0.42 on the
            skateboard (push-off-1.0 seed 0 measured 0.40-0.44 at the roll wave's 0.1 rad),
            None elsewhere.
        speed_preview: Where the ride's commands are planned ahead (the rider's
            ``command_preview``), the manoeuvre follows the speed command planned for the
            end of the MPC's horizon (0.4 s ahead), as the yaw rate and the deck roll are
            read over the horizon: the rider leans into a planned speed step before it
            comes, where the closed loop otherwise lags it by about 0.2 s on top of the
            library's own lean-in. True on the Hovershoes: velocity-steps seed 0, velocity
            RMSE 0.1046 read at once, 0.0786 / 0.0644 / 0.0531 / 0.0461 / 0.0436 / 0.0552
            m/s read 0.2 / 0.3 / 0.4 / 0.5 / 0.6 / 0.8 s ahead (the horizon's 0.4 s taken,
            not the best). True on the Segway: velocity-steps seeds 0/1, 0.4069/0.4060 ->
            0.2435/0.2458 m/s (the ``pd`` baseline's 0.3986 seed 0); yaw-steps yaw-rate RMSE
            0.0608/0.0604 -> 0.0611/0.0605 rad/s, circle 0.0276 either way (its speed RMSE
            0.0223 -> 0.0215), push 0.0327 m/s either way. False on the skateboard, whose
            push-offs are judged from their command.
        plan_latency: Control ticks (2 ms each) from the state an MPC solve starts from to
            the tick its plan takes over (:class:`~ridempc.mpc.rider.MpcRider`): with 1,
            OSQP iterates in a thread beside the control loop, as on the robots; with 0
            the loop waits for it in the tick. 1 on the Hovershoes, where the loop needs the
            thread to keep to real time (velocity-steps, 6 s: 2.04 -> 1.98 ms a tick, real-
            time factor 0.98 -> 1.01) and every ride checked rides with it (seeds 0-7 of
            velocity-steps, yaw-steps, push and offset-start). 0 on the Segway: its ride
            from a standstill, seed 6, fell at 1.7-3.0 s with the plan a tick late (push,
            velocity-steps, yaw-steps, stand-still; the platform rings at the start, and
            the delay feeds it), where seeds 0-5 and 7 rode and the PD rides seed 6. 0 on
            the skateboard: with it, push-off-1.0 fell on seeds 1, 13, 14 and 15 of 0-15,
            against 12, 13 and 14 without: the push-offs are fragile either way (the
            trunk tips towards the pushing foot before it lands), the delay no cure.
        roll_lead: How far ahead of each horizon node the commanded deck roll is read [s]
            (:meth:`~ridempc.mpc.rider.MpcRider._roll_horizon`): the closed loop's deck
            follows the plan's roll late (the MPC's steps, the whole-body QP's tracking,
            the trucks), so the plan is made for a command that far on. 0.08 s on the
            skateboard, the lag measured on its roll waves (a sine fitted to the deck's
            roll against the command's, 3 s period: 78 ms on roll-tracking seed 0, 88-136
            ms after the push-offs), which took roll-tracking seed 0's roll RMSE from
            0.0146 to 0.0091 rad at 0.066 s and 0.0097 at 0.1 s, and push-off-0.5 seed
            14's from 0.0200 to 0.0127 and 0.0101; 0 elsewhere (no deck roll).
        settle: What the reference does after its end besides riding on
            (:mod:`~ridempc.mpc.settle`), or None for nothing: on the skateboard the dog
            settles back over its four feet in 1.5 s (``settle_over_feet``), where held at
            the library's last node it balanced on with 80-97 % of its weight on its front
            feet. Push-off-1.0, seeds 0-31: seed 25 fell at 15.05 s held and rides settled
            (seed 18 fell either way, in its last stroke, before the settle, until the
            library's pushes lifted the foot unloaded, ``SkateOptions.liftoff_force``); None
            elsewhere.
    """

    pair: Pair
    contacts: tuple[str, ...]
    surfaces: ca.Function
    input_limits: Array
    max_force: float
    weight: float
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
    roll_lead: float = 0.0
    settle: Callable[[MotionReference], MotionReference] | None = None


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


def _skateboard() -> MpcPair:
    robot, board = skate_models()
    nf, nr = robot.n_feet, 12 + robot.n_joints
    x = ca.SX.sym("x", nr + len(BOARD_STATE))
    rotation, _ = deck_frame(board, x[nr:])
    surfaces = ca.Function("contact_surfaces", [x], [ca.horzcat(*[rotation] * nf)])
    limits = np.concatenate([np.full(3 * nf, np.inf), robot.speed_limit])
    # The library's bound on each force component (skate_problem: twice the weight).
    pair = load_pair(robot.name, "skateboard")
    weight = robot.mass * GRAVITY
    return MpcPair(
        pair,
        robot.feet,
        surfaces,
        limits,
        2.0 * weight,
        weight,
        roll_observer=0.3,
        swing_force_step=10.0,
        push_tolerances=MappingProxyType({"vx": 0.0125, "board_v": 0.05}),
        push_max_target=0.7,
        stance_roll=0.42,
        roll_lead=0.08,
        settle=partial(settle_over_feet, robot=robot, duration=SETTLE_TIME),
    )


def _ride(
    robot: str,
    board: str,
    pyramid: str = "box",
    force_time_constant: float | None = None,
    terminal_factor: float = 10.0,
    start_speed: float = 0.0,
    speed_preview: bool = False,
    plan_latency: int = 0,
) -> MpcPair:
    rider, wheeled = ride_models(robot, board)
    layout = ride_layout(rider, wheeled)
    x = ca.SX.sym("x", 12 + len(wheeled.state_names))
    rotations = [wheeled.pose(x[12:], platform)[0] for platform in layout["platform_of"]]
    surfaces = ca.Function("contact_surfaces", [x], [ca.horzcat(*rotations)])
    limits = np.concatenate([np.full(3 * rider.n_contacts, np.inf), wheeled.input_bound])
    # The library's bound: one contact may carry the whole weight (ride_problem).
    pair = load_pair(robot, board)
    weight = rider.body.mass * GRAVITY
    tipping: tuple[tuple[tuple[int, ...], float], ...] = ()
    loaded = load_board(board)
    params = loaded.params if loaded is not None else None
    if isinstance(params, HovershoesParameters):
        ratio = 0.5 * params.wheel_width / params.platform_height
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
        pyramid,
        tipping,
        force_time_constant,
        terminal_factor,
        start_speed,
        speed_preview=speed_preview,
        plan_latency=plan_latency,
    )


MPC_PAIRS: dict[str, Callable[[], MpcPair]] = {
    "cyberdog2-skateboard": _skateboard,
    "cassie-hovershoes": partial(
        _ride,
        "cassie",
        "hovershoes",
        pyramid="diamond",
        force_time_constant=0.042,
        terminal_factor=30.0,
        start_speed=0.06,
        speed_preview=True,
        plan_latency=1,
    ),
    "cassie-segway": partial(_ride, "cassie", "segway", speed_preview=True),
}


@cache
def load_mpc_pair(robot: str, board: str) -> MpcPair:
    """The MPC's view of a pair (built once per process).

    Raises:
        UnknownNameError: No MPC for that pair; the message lists those that have one.
    """
    name = f"{robot}-{board}"
    if name not in MPC_PAIRS:
        raise UnknownNameError("robot-board pair for the MPC", name, MPC_PAIRS)
    return MPC_PAIRS[name]()
