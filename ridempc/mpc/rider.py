"""``mpc``: the skateboard paper's pipeline (section V) riding any pair with an MPC library.

Every 2 ms (500 Hz) the rider

1. estimates its state from the sensors (:class:`~ridempc.estimation.StateEstimator`, the
   board from its own feet), and its mass and centre of mass from its stance's loads
   (:mod:`ridempc.mpc.payload`: a payload, or a lighter rider), which the map's and the
   whole-body QP's models carry and the MPC's vertical rate takes as a drift;
2. every 15th tick (30 Hz), maps the estimate into the library frame
   (:class:`~ridempc.mpc.state_map.StateMap`, which follows the board sideways onto the
   reference's line: speeds and turn rates are commanded, not a path; on a board the
   rider cannot steer, the Segway, it also turns with the board's direction of travel)
   and solves the linear MPC
   (:class:`~ridempc.mpc.controller.LinearMpc`; on the Segway and the skateboard the
   problem is built and solved in a process of its own, as the robots run their MPC beside
   their WBC, from what the tick sends it (:meth:`MpcRider._build_and_run`, ``off_tick``;
   on the Hovershoes in a thread), and the plan takes over two ticks (4 ms; the Hovershoes
   one) after the MPC's tick, solved from the state predicted there by the reduced model
   (:mod:`ridempc.mpc.delay`; the Hovershoes' from the tick's state, its time shifted: the
   pair's ``predict_start``), waited for then whatever the machine, the ticks between
   following the previous plan in its own library frame: the pair's ``plan_latency``) on
   the manoeuvre the command asks for
   (:mod:`ridempc.mpc.manoeuvre`): a push-off or a speed change follows its library
   trajectory, then rides on steadily (on the skateboard, which only a push drives, it
   coasts: the steady ride is slowed to the board's speed,
   :meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.coasting`, and once it has slowed below
   the command it pushes again from the rolling board, the library's ``repush``,
   :meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.repush`); a commanded deck roll
   replaces the reference's roll, and on the skateboard turns the reference's heading at
   the rate the roll steers (eq. 14), a commanded yaw rate adding the roll that steers it
   (:mod:`ridempc.boards.skateboard.steering`); on the Segway, whose knee bar the plan cannot push,
   the rider crouches into the robot's riding keyframe and leans into the bar: a yaw-rate
   loop moves the reference's centre of mass sideways, and riding, the reference's
   headings and the heading the frame follows turn at the commanded rate and the frame's
   turn pulls the centre of mass outwards in the plan (:mod:`ridempc.mpc.lean`);
   on the Hovershoes the MPC also sees where each foot stands along its shoe and each
   shoe's drag, which the reduced model leaves out, as fitted from the shoes' balances by
   :class:`~ridempc.mpc.shoe_observer.ShoeObserver` at 500 Hz, each shoe's heading is
   read off its direction of travel where its foot's toe line has crept round on it
   (:mod:`ridempc.mpc.shoe_heading`, at 500 Hz, for the WBC too), and each shoe's heading
   reference is turned towards its line (:mod:`ridempc.mpc.guidance`); on the
   skateboard, in four-leg balancing, the MPC's deck-roll row carries an integrated
   estimate of the torque its model misses (:mod:`ridempc.mpc.roll_observer`), held while
   the feet of one side are off the deck or at their least force, the commanded roll is
   held to what the feet's estimated stance can hold (:mod:`ridempc.mpc.stance`), and while
   a foot swings the first step's deck forces are drawn to the last plan's
   (:mod:`ridempc.mpc.input_rate`);
3. turns the plan into whole-body targets, interpolated between the plan's first two nodes
   over the 1/30 s step: centre of mass :math:`c^*(t)` and velocity, base orientation from
   the Z-Y-X angles, where the pair asks for it (``wbc.feedforward``) the plan's
   first-step accelerations :math:`(v_1 - v_0)/\\Delta t` and
   :math:`(\\omega_1 - \\omega_0)/\\Delta t` fed forward, the first input's contact forces
   (summed per foot; on the Hovershoes low-passed from solve to solve,
   :mod:`ridempc.mpc.force_filter`), the feet in
   contact as the schedule has them over the step, and, for a foot the schedule lifts, a
   swing target where the reference puts it, carried by the estimated board
   (:mod:`ridempc.mpc.swing`), and on the Hovershoes each shoe's fitted drag as its
   rolling platform's acceleration (:meth:`~ridempc.mpc.shoe_observer.ShoeObserver.drift`);
   and solves the 500 Hz whole-body QP
   (:class:`~ridempc.wbc.WholeBodyController`, its posture task holding the reference's
   joint angles where the library has them, the dog's, else the robot's riding posture
   on the board, its stance unless a riding keyframe is given: the stance would hold the
   dog's trunk above the reference's crouch). A foot the
   schedule puts on the ground (a push-off) stands on the ground for the WBC and the
   estimator, not on the board; a foot it lifts is left out of the board's estimate even
   if it touches something;
4. sends the QP's torques as feedforward, each led over its motor's torque delay
   (:mod:`~ridempc.wbc.torque_lead`), with its joint targets to the motor PD, at the
   pair's ``tracking_gain_scale`` of its default stiffnesses; a delayed motor's damping is
   the one of largest phase margin for that stiffness at the joint's inertia in the riding
   posture (:func:`~ridempc.robots.delay_margin.tracking_damping`), the others' the same
   scale of their default damping.

**Fallback.** The whole-body QP always returns a command (slack on its soft rows where it
has no solution as posed, :mod:`ridempc.wbc.elastic`). If the MPC's QP fails (its
previous plan shifted by one step is then used), the whole-body QP needs slack or still
fails, anything raises, the estimate is not finite, or the state strays beyond
:data:`~ridempc.mpc.handover.HANDOVER_DEVIATION` of its reference, or will be within a
divergence time at the rate it grows beyond what its plan expects, until the MPC has held
the rider settled since the start or its last return (:mod:`~ridempc.mpc.divergence`),
or a push from outside changes the rider's velocity beyond the pair's ``impulse`` band
(:mod:`~ridempc.mpc.impulse`), the ride is handed to
the pair's PD baseline (:data:`BACKUP_LAW`, in standby beside the MPC, reading the rider's
estimate), the motor commands blended, and handed back once the MPC's plans have solved
and its state has stayed near the reference for a while (:mod:`ridempc.mpc.handover`);
each handover is in ``summary()``'s ``fallbacks``. With the pair's ``takeover`` stage the
ride starts on that backup, the MPC planning beside it in a frame laid on the board and
its payload estimate learning, and the MPC takes over once ready
(:mod:`~ridempc.mpc.readiness`; when: ``summary()``'s ``mpc_takeover_s``). Only where the
backup too has no finite command are the joints held where they are (``safe_hold``).
"""

from __future__ import annotations

import copy
import math
import time
from concurrent.futures import Future
from dataclasses import replace
from functools import cache, partial
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.boards.canonical import BoardState, board_state_columns
from ridempc.boards.hovershoes.parameters import HovershoesParameters
from ridempc.boards.skateboard.reduced import yaw_rate
from ridempc.boards.skateboard.steering import RollSteering
from ridempc.controllers.base import Controller
from ridempc.errors import RidempcError
from ridempc.estimation import EstimatedState, StateEstimator
from ridempc.mpc.controller import LinearMpc, MpcSettings
from ridempc.mpc.delay import predicted_start
from ridempc.mpc.disturbance import DisturbanceObserver, disturbance_rows
from ridempc.mpc.divergence import DivergentDeviation, Probation
from ridempc.mpc.drop import DropDetector
from ridempc.mpc.foot_spread import spread_lines
from ridempc.mpc.force_filter import ForceFilter
from ridempc.mpc.guidance import steer_onto_lines
from ridempc.mpc.handover import (
    HANDOVER_DEVIATION,
    RETURN_DEVIATION,
    RETURN_DWELL_S,
    STANDBY_DIVIDER,
    Handover,
    deviation,
    share_estimator,
    standby_every,
)
from ridempc.mpc.impulse import ImpulseObserver, ImpulseTrigger
from ridempc.mpc.input_rate import hold_first_input
from ridempc.mpc.lean import Crouch, LeanSteering
from ridempc.mpc.manoeuvre import (
    HOLD,
    REPUSH,
    REPUSH_BAND,
    Manoeuvre,
    ManoeuvreSelector,
    StateLayout,
)
from ridempc.mpc.pairs import check_library_names, load_mpc_pair
from ridempc.mpc.payload import PayloadEstimator
from ridempc.mpc.plan import Plan
from ridempc.mpc.plan_targets import PlanReader
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.push_gain import shifted_speeds
from ridempc.mpc.push_handover import deviation_deferred
from ridempc.mpc.push_side import PushSide, first_stride
from ridempc.mpc.readiness import start_readiness
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.riding_posture import ride_qpos
from ridempc.mpc.roll_observer import RollObserver
from ridempc.mpc.shoe_heading import ShoeHeading
from ridempc.mpc.shoe_observer import ShoeObserver
from ridempc.mpc.solver_process import Reply, SolverProcess, forks
from ridempc.mpc.solver_thread import SolverThread
from ridempc.mpc.stagger import standby_phase
from ridempc.mpc.stance import StanceLimit
from ridempc.mpc.state_map import PlanarFrame, StateMap, forward_speed
from ridempc.mpc.statics import StaticShift
from ridempc.mpc.swing import VELOCITY_STEP, ReferenceFeet
from ridempc.mpc.switch_blend import SwitchBlend
from ridempc.robots.delay_margin import tracking_damping
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command, Scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket
from ridempc.solvers import solver_for
from ridempc.trajopt.platforms import HovershoesBoard, wheeled_board
from ridempc.trajopt.schedule import Contact
from ridempc.trajopt.skateboard import skateboard_model
from ridempc.wbc import WbcTargets, WholeBodyController, to_motor_command
from ridempc.wbc.controller import motor_posture
from ridempc.wbc.platforms import RollingPlatform
from ridempc.wbc.qp import WbcFailed
from ridempc.wbc.settings import WbcSettings
from ridempc.wbc.torque_lead import TorqueLead

__all__ = ["BACKUP_LAW", "MpcRider", "platform_feet", "rolling_platforms"]

Array = NDArray[np.float64]
MPC_DIVIDER: int = 15  # 500 Hz / 15 = 33.3 Hz ~ the paper's 30 Hz; the MPC step stays 1/30 s
# The law the ride is handed to when the MPC or its QP fails (ridempc.mpc.handover): the
# pair's PD baseline, which balances every pair from the same sensors.
BACKUP_LAW: str = "pd"
# [s] how long from the ride's start the backup's standby runs every tick while the MPC is
# on probation: an unknown model (a payload's offset) tips the rider within 0.5-1 s of the
# start, where the backup's filters are still settling from rest; later its 33 Hz standby
# keeps them current (every tick throughout cost 8 % of the loop's speed).
STANDBY_WARMUP_S: float = 1.0
# Least plan_latency [ticks] whose solves go to the solver process: at 1 the loop takes the
# plan up after the next tick's simulation and estimate, about 0.5 ms after sending the
# state, where the process builds and solves in 2.3 ms (Hovershoes, median) and the thread,
# which overlaps OSQP's iterations with the loop (0.7 ms of building holds the lock), waits
# less (docs/tuning.md).
PROCESS_MIN_LATENCY: int = 2


class _BuildInputs(NamedTuple):
    """What an MPC problem is built from, as the loop has it at the MPC's tick: the
    reference's time [s], the mapped state, the rates' drift (or None), the tick's time
    [s], the board's speed [m/s], the commanded roll at the horizon's nodes [rad], the
    turn over its steps [rad/s], the turn so far [rad], whether the rider coasts, whether
    the manoeuvre switched at this tick, the lean loop (a copy, or None), the shoes'
    observer (frozen, or None), the manoeuvre's kind and target, the plan in force's
    first input (or None), the contacts of the last MPC step, the reference tracked
    when it changed at this tick (else None), whether any manoeuvre began at this tick,
    and the commanded lateral offset of the feet [m] (:mod:`~ridempc.mpc.foot_spread`);
    and the delay [s] from the tick to the plan's take-up over which ``x0`` is predicted
    (:mod:`~ridempc.mpc.delay`; ``t_ref`` and ``now`` are then the take-up's)."""

    t_ref: float
    x0: Array
    drift: Array | None
    now: float
    speed: float
    roll: Array
    turn: Array
    turned: float
    coasting: bool
    switched: bool
    lean: LeanSteering | None
    shoes: ShoeObserver | None
    manoeuvre: tuple[str, float]
    first_input: Array | None
    contacts: tuple[Contact, ...]
    reference: MotionReference | None
    began: bool
    lateral_offset: float
    delay: float = 0.0


class _Built(NamedTuple):
    """An MPC problem built and solved (:meth:`MpcRider._build_and_run`): its plan, the
    contacts of its first step, the time spent building it [s], the QP's failures so far,
    the problem (None when sent back from the solver process without it) and how far its
    initial state lies from its reference (:func:`~ridempc.mpc.handover.deviation`) and how
    far its plan's next state lies from the next reference [-]."""

    plan: Plan
    contacts: tuple[Contact, ...]
    build_s: float
    failures: int
    problem: MpcProblem | None
    deviation: float
    expected: float


class _PendingSolve(NamedTuple):
    """An MPC solve under way: the library frame its problem is in, the time of the state
    it starts from [s], the tick its plan takes over, and its built and solved problem to
    come (None when built and solved in the tick)."""

    frame: PlanarFrame
    time: float
    due: int
    reply: Future[_Built] | Reply[_Built] | None = None


def _backup(robot: Robot, board: str) -> Controller:
    """The registry's :data:`BACKUP_LAW` for ``robot`` on ``board``."""
    from ridempc.controllers.registry import CONTROLLERS  # the registry imports this module

    return CONTROLLERS[BACKUP_LAW](robot, board)


@cache
def _solver_thread() -> SolverThread:
    """The thread the MPC's solves run in beside the control loop, one for the process
    (made at its first use): a rider per ride, and rides one after another (``compare``'s
    seeds), would otherwise each leave an idle thread behind."""
    return SolverThread("mpc")


def platform_feet(robot: Robot, platforms: int) -> tuple[tuple[str, ...], ...]:
    """Feet per platform: one each when the board has a platform per foot, else all on one."""
    feet = robot.params.foot_bodies
    if platforms == len(feet):
        return tuple((foot,) for foot in feet)
    return (feet,)


def rolling_platforms(board: Board | None) -> tuple[RollingPlatform, ...]:
    """The platforms that the rider's push moves, as the WBC sees them: each Hovershoe, the
    bare shoe with its identified drive (:mod:`ridempc.wbc.platforms`); the skateboard's deck,
    its translating mass with no drive (3.2 kg under a 9 kg dog: taken for ground, the deck
    feet would push it past its plan as the pusher returns); none otherwise."""
    features = board.kind.features if board is not None else frozenset()
    if board is not None and "deck_roll" in features:
        return (RollingPlatform(mass=skateboard_model(board).mass, drive=0.0),)
    if board is None or "shoes" not in features:
        return ()
    shoes = cast(HovershoesBoard, wheeled_board(board))
    params = cast(HovershoesParameters, board.params)
    shoe = RollingPlatform(
        mass=shoes.shoe_mass,
        drive=shoes.reduced.c4,
        tread=params.wheel_width,
        height=params.platform_height,
    )
    return (shoe,) * shoes.n_platforms


def _to_deck(yaw: float, planar: Array) -> Array:
    """Horizontal vectors [m] (..., 2), world axes, in the deck's (along, across) axes."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.asarray(planar, dtype=float) @ np.array([[c, -s], [s, c]])


class MpcRider(Controller):
    """MPC at 30 Hz over the robot and its board, whole-body QP at 500 Hz.

    Args:
        robot: The rider.
        board: The board's name; the pair needs an MPC library.
        settings: MPC settings.
        wbc_solver: The whole-body QP's solver (:data:`~ridempc.wbc.settings.SOLVERS`);
            None: the registry's (:data:`~ridempc.solvers.QP_KINDS`).
        backup: The law the ride is handed to when the MPC fails
            (:mod:`~ridempc.mpc.handover`); None: the registry's :data:`BACKUP_LAW` for
            the pair.

    Raises:
        UnknownNameError: No MPC for this robot-board pair.
        ConfigError: Its library is missing or corrupt, or an unknown ``wbc_solver``.
    """

    rate_hz = 500.0
    # Where a solve with a ``plan_latency`` is built and run (its plan taken up
    # ``plan_latency`` ticks on whichever: the same ride, bit for bit): ``process``, a
    # child process on the other core (mpc/solver_process.py) from PROCESS_MIN_LATENCY
    # on, else, or where the process cannot fork (in a sweep's worker, off the main
    # thread), the thread; ``thread``, the solver thread (its Python holds the loop's
    # lock: only OSQP's iterations run beside the loop); ``tick``, in its tick.
    off_tick: str = "process"
    # Whether the solver process sends each problem back with its plan (the bench keeps
    # them; the ride needs the plan only).
    keeps_problems: bool = False

    def __init__(
        self,
        robot: Robot,
        board: str,
        settings: MpcSettings | None = None,
        wbc_solver: str | None = None,
        plan_latency: int | None = None,
        backup: Controller | None = None,
    ) -> None:
        super().__init__(robot, board)
        from ridempc.boards import load_board

        self.pair = load_mpc_pair(robot.name, board)
        stages = self.pair.description.stages  # the pair file's per-pair mechanisms
        tuning = self.pair.description.wbc
        # Ticks from the state a solve starts from to the tick its plan takes over: with 1
        # or more OSQP iterates in a thread beside the loop and the ticks between follow
        # the previous plan; waited for at that tick, so that a ride does not depend on the
        # machine (the pair's ``plan_latency`` unless given).
        latency = self.pair.plan_latency if plan_latency is None else plan_latency
        if latency < 0 or latency >= MPC_DIVIDER:
            raise ValueError(f"plan_latency must be 0 to {MPC_DIVIDER - 1} ticks, got {latency}")
        self.plan_latency = latency
        # A plan taken up late solved from the state predicted at its take-up (mpc/delay.py),
        # else from the tick's, its time shifted (the pair's ``predict_start``).
        self.predicts_start = self.pair.predict_start
        loaded = load_board(board)
        n_platforms = len(loaded.params.platform_sites) if loaded is not None else 1
        self.platform_feet = platform_feet(robot, n_platforms)
        self.estimator = StateEstimator(
            robot,
            platforms=self.platform_feet,
            support_height=loaded.platform_top if loaded is not None else 0.0,
        )
        self.pinocchio = build_pinocchio_robot(robot)
        self.selector = ManoeuvreSelector(robot.name, board)
        symmetry = self.pair.symmetry  # each re-push from the side its turn needs
        self.push_side = (
            PushSide(symmetry) if symmetry is not None and REPUSH in self.selector.targets else None
        )
        first = self.selector.initial()
        self.mpc = LinearMpc.from_library(
            robot.name, board, first.library_kind, first.target, settings
        )
        # the rider's mass and centre of mass from its stance (ridempc.mpc.payload)
        self.payload = (
            PayloadEstimator(robot, self.pinocchio, self.mpc.settings.dt)
            if stages.payload is not None
            else None
        )
        names = self.mpc.reference.input_names
        check_library_names(self.pair.description, self.mpc.reference)
        # Board inputs of the library that this rider does not realise (the pair file's
        # ``unrealised_inputs``), held at zero in the MPC.
        unrealised = self.pair.description.mpc.unrealised_inputs
        pinned = {n: 0.0 for n in unrealised if n in names}
        self.mpc.fix_inputs({**pinned, **self.mpc.settings.fixed_inputs})
        # Yaw-rate commands are laid over the reference only where the rider can turn the
        # board (not the Segway with its knee bar pinned, which the lean turns).
        self.steers = self.mpc.steers()
        # A board with a yaw rate that the rider cannot drive (the Segway's): the library
        # frame turns with its heading (StateMap.follow_sideways).
        # where each board state is in the MPC's state, by its canonical quantity
        columns = board_state_columns(self.mpc.reference.state_names, self.pair.board_states)
        yaw_rates = any(state.quantity == "yaw_rate" for state in columns)
        self._follows_heading = yaw_rates and not self.steers
        # A board turned by a bar the legs push (the Segway's knee bar, held at zero in the
        # plan): the rider crouches to reach it and leans into it (ridempc.mpc.lean).
        self.crouch = Crouch.of(robot, board)
        self.lean = LeanSteering() if stages.lean is not None and not self.steers else None
        self.disturbance = self._disturbance_observer()  # offset-free MPC (mpc/disturbance.py)
        self.manoeuvre: Manoeuvre = first
        reference = self.mpc.reference
        self.layout = StateLayout.from_pair(reference.state_names, self.pair)
        self.map = StateMap(
            self.pinocchio, reference.state_names, self.pair.board_states, base=self.pair.base
        )
        # Cassie's leaf springs as rigid joints held at their deflection: as passive torques
        # the estimator's spring deflection (about twice the true one, through the soft
        # achilles-rod constraint) drives the QP off (see the WBC's tests).
        # The MPC's forces weigh the pair file's ``wbc.force_weight`` (the WBC's own default
        # is 1): their distribution over the feet is what rolls a deck or a platform, and the
        # CoM and orientation tasks leave it free (measurements: docs/tuning.md, "Pair files").
        sprung = bool(np.any(self.pinocchio.spring_stiffness > 0.0))
        settings_wbc = WbcSettings(
            springs="rigid" if sprung else "passive",
            force_weight=tuning.force_weight,
            pyramid=self.pair.pyramid,
            solver=wbc_solver or solver_for("wbc"),
        )
        self.wbc = WholeBodyController(
            robot,
            settings_wbc,
            pinocchio=self.pinocchio,
            posture=motor_posture(self.pinocchio, robot, ride_qpos(robot, board)),
            platforms=rolling_platforms(loaded),
        )
        self._feedforward = tuning.feedforward
        tau = self.pair.force_time_constant  # the forces the WBC gets, low-passed
        self.force_filter = ForceFilter(tau) if tau is not None else None
        scale = tuning.tracking_gain_scale  # the QP's torques lead, the PD follows
        self.kp = scale * np.array([m.kp for m in robot.motors])
        self.kd = tracking_damping(  # each delayed loop damped at its largest margin
            robot.mj_model,
            ride_qpos(robot, board),
            robot.motors,
            self.kp,
            scale * np.array([m.kd for m in robot.motors]),
            1.0 / DEFAULT_PHYSICS_HZ,
        )
        self.torque_lead = TorqueLead(robot, self.wbc.settings.dt)  # sent ahead of the delay
        self._contact_foot = self._contacts_to_feet(reference.contact_names)
        self._read_plan = PlanReader(
            self.layout.names,
            self.layout.base_prefix,
            reference.force_index,
            self._contact_foot,
            len(robot.params.foot_bodies),
            self._feedforward,
            self.mpc.settings.dt,
        )
        # The library's contacts are the WBC's sites (Cassie's toe lines): the WBC then
        # applies the MPC's centre of pressure along each foot, not an even share.
        self._sites_match = tuple(reference.contact_names) == tuple(robot.params.contact_sites)
        self.shoes = self._shoe_observer(loaded)
        # each shoe's heading from its direction of travel: the soles creep round on the pads
        self.shoe_heading = (
            ShoeHeading(self.shoes.platforms)
            if self.shoes is not None and stages.shoe_heading is not None
            else None
        )
        self._guidance = stages.guidance is not None  # shoe headings turned onto their lines
        quantities = ("x", "y", "heading", "speed")  # each shoe's, in the MPC's state
        self._shoe_columns = (
            tuple(
                tuple(columns[BoardState(k, q)] for q in quantities)
                for k in sorted({state.platform for state in columns})
            )
            if self.shoes is not None
            else ()
        )
        rolls = stages.roll_steering is not None or stages.roll_observer is not None
        deck = skateboard_model(loaded).reduced if loaded is not None and rolls else None
        steers = deck if stages.roll_steering is not None else None
        self._steer_gain = steers.steer_gain if steers is not None else None
        # a yaw-rate command steered by the deck's roll, eq. (14) inverted
        self.roll_steering = RollSteering(gain=steers.steer_gain) if steers is not None else None
        self._blend: SwitchBlend | None = None  # a re-push's reference blended in
        gain = self.pair.roll_observer
        roll, roll_rate = BoardState(0, "roll"), BoardState(0, "roll_rate")  # the deck's
        self.roll_observer = (
            RollObserver(columns[roll], columns[roll_rate], deck, gain)
            if deck is not None and gain is not None and roll_rate in columns
            else None
        )
        self.stance = (
            StanceLimit(self.pair.stance_roll)
            if self.roll_observer is not None and self.pair.stance_roll is not None
            else None
        )
        # Feet per side of the deck for a rider standing on it on two sides of feet (a
        # quadruped's two), 0 for one foot a side: the roll observer's and the stance's sides.
        n_feet = len(robot.params.foot_bodies)
        self._side_feet = n_feet // 2 if n_feet >= 4 and n_feet % 2 == 0 else 0
        self.feet = ReferenceFeet(
            self.wbc.model, reference.state_names, self.layout.base_prefix, self.layout.board_pose
        )
        self._support: tuple[Contact, ...] | None = None  # per foot, this MPC step
        self._contacts: tuple[Contact, ...] = ()  # per library contact, the last MPC step
        self._tick = 0
        self._plan: Plan | None = None
        self._plan_frame = PlanarFrame()
        self._last_problem: MpcProblem | None = None
        self._plan_time = 0.0
        self._command_roll: tuple[float, float] | None = None
        self._lean_shift: tuple[tuple[str, float], StaticShift] | None = None
        self._turned = 0.0  # [rad] the commanded yaw rate integrated over the ride
        self._turn_time: float | None = None
        self._turn_rate = 0.0
        self._hold: MotorCommand | None = None
        self._wbc_failures = 0  # in all
        self._hold_reason: str | None = None
        self._hold_time: float | None = None
        self._mpc_ms: list[float] = []  # each tick: building the problem and solving it
        self._mpc_qp_ms: list[float] = []  # each tick's QP: updating it and solving it
        self._mpc_main_s = 0.0  # [s] the MPC's time in the control loop's own thread
        self._pending: _PendingSolve | None = None
        self._worker: SolverProcess[_BuildInputs, _Built] | None = None
        self._sent_reference: MotionReference | None = None  # the last one the build got
        self._mpc_failures = 0  # the MPC's fallbacks, as of the last plan taken up
        self._wbc_ms: list[float] = []
        self._wbc_slack_max = 0.0  # the largest slack the WBC's soft rows took
        self._deviation = 0.0  # [-] the MPC's state from its reference (handover.deviation)
        self._divergence = DivergentDeviation()  # where that deviation is heading
        self._probation = Probation()  # whether the MPC has shown its model holds the rider
        # the platforms falling away under the feet (a step), with the ``drop`` stage
        self._drop = DropDetector() if self.pair.description.stages.drop is not None else None
        self._com_height = 1.0  # [m] the centre of mass over the feet, at the last MPC tick
        law = backup if backup is not None else _backup(robot, board)
        shared = share_estimator(law, self.estimator)  # one filter for both
        # the backup's standby in full every tick while the MPC is on its first probation, in
        # the ride's first STANDBY_WARMUP_S: the backup's filters start there from rest, and
        # at 33 Hz over the first 0.06 s they had not caught up when handed the ride
        self._standby_every = STANDBY_DIVIDER if shared else 1
        self.handover = Handover(
            law,
            standby_every=1,
            standby_phase=standby_phase(MPC_DIVIDER, latency),  # off the MPC's and plan's ticks
        )
        # the ride starts on the backup until the MPC is ready (mpc/readiness.py)
        self.readiness = start_readiness(stages.takeover, RETURN_DWELL_S)
        if self.readiness is not None:
            self.handover.start_on_backup()
        self._diagnostics: dict[str, float] = {}
        # a push the MPC cannot ride handed to the backup at once (mpc/impulse.py)
        bands = stages.impulse
        mass = self.wbc.model.mass  # [kg] the rider's, as modelled
        self.impulse = ImpulseObserver(mass) if bands is not None else None
        self._push_trigger = ImpulseTrigger(bands.band, bands.sideways) if bands else None
        self._contact_force = np.zeros(3)  # [N] the whole-body QP's, summed over the feet
        self._com_velocity = np.zeros(3)  # [m/s] at the whole-body QP's last estimate

    def _disturbance_observer(self) -> DisturbanceObserver | None:
        """With the ``disturbance`` stage, the observer of the model's steady error on its
        velocity rows (:mod:`~ridempc.mpc.disturbance`)."""
        stage = self.pair.description.stages.disturbance
        if stage is None:
            return None
        names = self.mpc.reference.state_names
        rows, angular = disturbance_rows(names, self.pair.board_states, stage.rows)
        planar = (names.index("vx"), names.index("vy")) if "vx" in names else None
        return DisturbanceObserver(
            rows, angular, stage.time_constant, stage.max_linear, stage.max_angular, planar
        )

    def _observe_disturbance(self, x0: Array, now: float, balancing: bool) -> Array:
        """The disturbance estimated from the last plan's prediction of ``x0``
        (:mod:`~ridempc.mpc.disturbance`), as a drift of the MPC's rates: estimated while
        balancing (holding or coasting), held through a manoeuvre (its accelerations are
        not a constant disturbance: estimated through ``velocity-steps``' speed changes the
        Hovershoes fell) and while the backup law rides (the plan is not followed)."""
        observer = self.disturbance
        assert observer is not None
        turn = math.remainder(self.map.frame.yaw - self._plan_frame.yaw, 2.0 * math.pi)
        elapsed, dt = now - self._plan_time, self.mpc.settings.dt
        hold = self.handover.on_backup or self._pending is not None or not balancing
        observer.update(x0, self._plan, now, elapsed, dt, turn, hold)
        self._diagnostics["disturbance_max"] = float(np.max(np.abs(observer.estimate), initial=0))
        return observer.drift(len(x0))

    def _shoe_observer(self, board: Board | None) -> ShoeObserver | None:
        """With the ``shoe_observer`` stage (Hovershoes), the observer of where each foot
        stands along its shoe and of each shoe's drag."""
        if board is None or self.pair.description.stages.shoe_observer is None:
            return None
        shoes = cast(HovershoesBoard, wheeled_board(board))
        names = self.wbc.model.foot_names
        platform_of = {foot: k for k, group in enumerate(self.platform_feet) for foot in group}
        sites = [platform_of.get(names[f], -1) for f in self.wbc.model.site_foot]
        return ShoeObserver(shoes, sites)

    def _mapped(self, estimate: EstimatedState) -> EstimatedState:
        """The estimate as the MPC sees it: each Hovershoe's origin on its axis."""
        return estimate if self.shoes is None else self.shoes.shift(estimate)

    def _contacts_to_feet(self, contacts: tuple[str, ...]) -> list[int]:
        """The foot (``foot_bodies`` index) each library contact belongs to."""
        model = self.robot.mj_model
        feet = list(self.robot.params.foot_bodies)
        out = []
        for contact in contacts:
            site = model.site(contact)
            body = model.body(int(site.bodyid[0])).name
            out.append(feet.index(body))
        return out

    # ------------------------------------------------------------------ loop

    def reset(self, sensors: SensorPacket) -> None:
        self.estimator.reset(sensors)
        self.map.reset()
        self.torque_lead.reset()
        if self._drop is not None:
            self._drop.reset()
        self._tick = 0
        self._plan = None
        estimate = self.estimator.state
        if estimate is not None:
            self._anchor(estimate, sensors.time)

    def _anchor(self, estimate: EstimatedState, now: float, turned: float = 0.0) -> None:
        """Lay the library frame so that the board's estimate lands on the reference's
        board at ``now``, its heading turned by ``turned`` [rad] (the turn the reference is
        given, :meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.with_turn`)."""
        self.manoeuvre = self.manoeuvre.started(now)
        state = self.mpc.reference.states_at(np.array([self.manoeuvre.reference_time(now)]))[0]
        x, y, heading = self.layout.board_pose(state)
        self.map.anchor(self._mapped(estimate), (x, y, heading + turned))

    def _safe_hold(self, sensors: SensorPacket, reason: str) -> MotorCommand:
        """The last resort, where even the backup law has no finite command: the joints
        held where they are with the robot's default gains from then on."""
        if self._hold is None:
            n = len(self.robot.motors)
            self._hold = MotorCommand.hold(self.robot.motors, np.array(sensors.joint_position[:n]))
            self._hold_reason = reason
            self._hold_time = sensors.time
        return self._hold

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        if self._hold is not None:
            self.estimator.update(sensors)
            return self._hold
        if self._tick == 0 and self.estimator.state is None:
            self.reset(sensors)
        else:
            self.estimator.update(sensors)
        primary, failure = self._primary(sensors, command)
        self._tick += 1
        starting = self.handover.starting
        out = self.handover.step(sensors, command, primary, failure, self._fit())
        if starting and not self.handover.starting:  # its rate measured the backup's ride
            self._divergence.reset()  # away from plans it did not follow
        self._diagnostics["on_backup"] = float(self.handover.on_backup)
        if not out.is_finite():
            return self._safe_hold(sensors, f"no finite command from the backup law: {failure}")
        return out

    def _primary(
        self, sensors: SensorPacket, command: Command
    ) -> tuple[MotorCommand | None, str | None]:
        """The MPC and whole-body QP's command this tick (None where they have none), and
        why they cannot ride (None if they can): the estimate not finite, a plan or a QP
        that failed, a QP that needed slack (:mod:`ridempc.wbc.elastic`), or the state
        beyond :data:`~ridempc.mpc.handover.HANDOVER_DEVIATION` of its reference, now or a
        divergence time on (:mod:`~ridempc.mpc.divergence`)."""
        estimate = self.estimator.state
        if estimate is None or not (
            np.isfinite(estimate.q).all() and np.isfinite(estimate.v).all()
        ):
            return None, "state estimate not finite"
        dropping = self._drop is not None and self._drop.update(self.estimator.contact.last_load)
        if self.shoe_heading is not None:
            estimate = self.shoe_heading(estimate)
        if self.payload is not None:
            loads = self.estimator.contact.last_load
            self.payload.accumulate(loads, estimate.contact, sensors.motor_torque, sensors.imu)
        try:
            if self._tick % MPC_DIVIDER == 0:
                self._mpc_tick(estimate, command, sensors.time)
            if self._pending is not None and self._tick >= self._pending.due:
                self._adopt_pending()
            if self._plan is None:
                return None, "no MPC plan"
            out = self._wbc_tick(estimate, sensors.time)
        except WbcFailed as exc:
            self._wbc_failures += 1
            return None, f"WbcFailed: {exc}"
        except RidempcError as exc:
            return None, f"{type(exc).__name__}: {exc}"
        pushed = self._pushed(estimate, sensors.time)
        if self._plan.fallback:
            return out, f"MPC plan failed (status {self._plan.status})"
        if dropping:
            return out, "every foot's load gone at once (a drop)"
        slack = self._diagnostics.get("wbc_slack", 0.0)
        if slack > 0.0:
            return out, f"whole-body QP infeasible (slack {slack:.3g})"
        if pushed is not None:
            return out, pushed
        repushing, start = self.manoeuvre.kind == REPUSH, self.manoeuvre.target - REPUSH_BAND
        stroke = deviation_deferred(repushing, self._support, self._speed(estimate), start)
        if self._deviation > HANDOVER_DEVIATION and not stroke:  # a re-push's stroke rides out
            return out, f"state {self._deviation:.2g} of its tolerances from the reference"
        if not self._probation.proven and self._divergence.value > HANDOVER_DEVIATION:
            return out, (
                f"state {self._deviation:.2g} of its tolerances from the reference, "
                f"growing at {self._divergence.rate:.2g}/s"
            )
        return out, None

    def _pushed(self, estimate: EstimatedState, now: float) -> str | None:
        """Why a push is beyond what the MPC rides (:mod:`~ridempc.mpc.impulse`), or None;
        the observer's window restarts while the backup rides (its forces are not the
        whole-body QP's)."""
        if self.impulse is None or self._push_trigger is None:
            return None
        if self.handover.on_backup:
            self.impulse.reset()
            return None
        impulse = self.impulse.update(now, self._com_velocity, self._contact_force)
        self._diagnostics["impulse"] = float(np.hypot(impulse[0], impulse[1]))
        heading = estimate.boards[0].yaw if estimate.boards else estimate.yaw
        return self._push_trigger(impulse, heading)

    def _fit(self) -> bool:
        """Whether the MPC may ride again: its plan solved (not the last one shifted) and
        the state near its reference (:func:`~ridempc.mpc.handover.deviation`) and not
        heading away from it faster than planned (:mod:`~ridempc.mpc.divergence`)."""
        plan = self._plan
        if self.handover.starting:  # the start's backup: until the MPC is ready
            return self.readiness is not None and self.readiness.ready
        settled = max(self._deviation, self._divergence.value) <= RETURN_DEVIATION
        return plan is not None and not plan.fallback and settled

    def hold_speed(self) -> None:
        self.selector.holds_speed = True  # the library's ``repush`` entries, where it has them

    def _mpc_tick(self, estimate: EstimatedState, command: Command, now: float) -> None:
        speed = self._speed(estimate)
        feet = np.asarray(estimate.foot_position, dtype=float)
        self._com_height = float(self.map.com(estimate)[2] - feet[:, 2].mean())
        # The manoeuvre is chosen, and its phase matched, on the CoM's speed, which the
        # reference's ``vx`` is: read off the feet, a Segway's speed swung +-0.3 m/s about
        # the rider's at 3-4 m/s, and one swing started the 4 m/s push 0.36 m/s ahead of
        # the rider (velocity-steps fell at 19.9 s).
        rider_speed = self.map.rider_speed(estimate)
        wanted = self.selector.select(
            self._speed_command(command, now), self.manoeuvre, now, rider_speed
        )
        if wanted is self.manoeuvre and self._coasting(self.manoeuvre.reference_time(now)):
            wanted = self.selector.repush(command, wanted, now, speed)  # slowed: push again
        began = wanted is not self.manoeuvre
        if began:
            self._divergence.reset()  # a new reference: its deviation steps, no divergence
        if began:
            self.mpc.retarget(wanted.library_kind, wanted.target)
            if wanted.kind == REPUSH and self.push_side is not None:
                self.mpc.reference = self.push_side.reference(
                    self.mpc.reference,
                    self._yaw_rate_ahead(command, now, first_stride(self.mpc.reference)),
                    self.pair.board_states,
                )
            reference = self.mpc.reference
            start = self.selector.phase_start(
                reference.times,
                reference.states[:, self.layout.names["vx"]],
                rider_speed,
                now,
                wanted.kind,
                self.pair.start_speed,
            )
            self.manoeuvre = replace(wanted, start=start)
            switched = wanted.kind == REPUSH  # from wherever the coast left the rider
            # any switch starts mid-turn: the reference's heading already carries the turn
            # made (anchored at the library's, a rider 0.2 rad into yaw-steps was asked to
            # turn back at once and fell in the push; one 0.67 rad into a course, in a stop)
            self._anchor(estimate, now, self._turned)
        else:
            switched = False
            if self.handover.starting and self.manoeuvre.kind == HOLD:  # the frame on the
                self._anchor(estimate, now, self._turned)  # board while the backup holds it
        t_ref = self.manoeuvre.reference_time(now)
        names, roll = self.layout.names, self._roll_horizon(command, now)
        mapped = self._mapped(estimate)
        coasting = self._coasting(t_ref)
        balancing = self.manoeuvre.kind == HOLD or coasting
        self._absorb_payload(estimate, balancing)
        pushing = Contact.GROUND in self._contacts  # a foot on the ground goes straight
        if balancing or (self.manoeuvre.kind == REPUSH and not pushing):
            roll = roll + self._steering_roll(command, now, speed)
        roll = self._stance_roll(roll, estimate, now, balancing)
        turn = self._yaw_rate_horizon(command, now) + self._roll_turn(roll, speed)
        here = self.mpc.reference.states_at(np.array([t_ref]))[0]  # the reference at t_ref
        if self.shoes is not None:  # the frame follows platform 0 onto its spread line
            here = spread_lines(here[None, :], self._shoe_columns, command.lateral_offset)[0]
        yaw_rate = estimate.yaw_rate
        if self.lean is not None:
            self.lean.update(now, command.yaw_rate, yaw_rate, speed)
        carried = self.lean.turn_rate if self.lean is not None else 0.0
        self._follow_board(mapped, here, turn, now, coasting, carried)
        x0 = self._unwrapped(self.map.state(mapped), here)
        started = time.perf_counter()
        drift = self._roll_drift(x0, now, balancing, estimate)
        if self.payload is not None:
            payload = self.payload.estimate.drift(len(x0), names["vz"])
            drift = payload if drift is None else drift + payload
        if self.disturbance is not None:
            observed = self._observe_disturbance(x0, now, balancing)
            drift = observed if drift is None else drift + observed
        if self.lean is not None:
            centrifugal = self.lean.drift(len(x0), names["vy"], speed, yaw_rate)
            if centrifugal is not None:
                drift = centrifugal if drift is None else drift + centrifugal
            self._diagnostics["lean_offset"] = self.lean.offset
        # the plan starts where it takes over (mpc/delay.py): the first plan is waited for
        late = self.plan_latency > 0 and self._plan is not None and self.predicts_start
        delay = self.plan_latency / self.rate_hz if late else 0.0
        inputs = _BuildInputs(  # what the loop's state says now, copied: the build may run
            self.manoeuvre.reference_time(now + delay),  # beside the loop's next ticks,
            x0,
            drift,  # which move the shoes' observer on
            now + delay,
            speed,
            roll,
            turn,
            self._turned,
            coasting,
            switched,
            copy.copy(self.lean),
            self.shoes.frozen() if self.shoes is not None else None,
            (self.manoeuvre.kind, self.manoeuvre.target),
            self._plan.first_input if self._plan is not None else None,
            self._contacts,
            None if self.mpc.reference is self._sent_reference else self.mpc.reference,
            began,
            command.lateral_offset,
            delay,
        )
        self._sent_reference = self.mpc.reference
        # the frame the plan is in: the map's moves on at the next tick, the plan only
        # when this one takes over
        pending = _PendingSolve(self.map.frame, now + delay, self._tick + self.plan_latency)
        if self.plan_latency == 0 or self._plan is None:  # the first plan is waited for
            self._adopt(pending, self._build_and_run(inputs))
        else:
            self._pending = pending._replace(reply=self._submit(inputs))
        self._mpc_main_s += time.perf_counter() - started

    def _submit(self, inputs: _BuildInputs) -> Future[_Built] | Reply[_Built]:
        """The build and solve of ``inputs`` started where ``off_tick`` says."""
        where = self.off_tick
        process = where == "process" and self.plan_latency >= PROCESS_MIN_LATENCY
        if process and (self._worker is not None or forks()):
            if self._worker is None:
                self._worker = SolverProcess(self._build_in_process)
            return self._worker.submit(inputs)
        if where in ("process", "thread"):
            return _solver_thread().submit(partial(self._build_and_run, inputs))
        future: Future[_Built] = Future()
        future.set_result(self._build_and_run(inputs))
        return future

    def close(self) -> None:
        """End the MPC's solver process, if one was started (at the end of a ride)."""
        if self._worker is not None:
            self._worker.close()
            self._worker = None

    def _build_and_run(self, inputs: _BuildInputs) -> _Built:
        """The MPC problem of one tick built from ``inputs`` (and the build's own state:
        the QP and its warm start, a re-push's blend, the crouch's start, the static
        shifts kept by key) and solved; in the loop's tick, the solver thread or the
        solver process (``off_tick``), the same either way."""
        started = time.perf_counter()
        if inputs.reference is not None:
            self.mpc.reference = inputs.reference
        x0 = inputs.x0
        if inputs.delay > 0.0 and inputs.first_input is not None:
            mpc = self.mpc
            x0 = predicted_start(
                mpc.model,
                mpc.reference,
                inputs.t_ref,
                x0,
                inputs.first_input,
                inputs.drift,
                inputs.delay,
                mpc.settings.dt,
            )
        problem = self._shaped(self.mpc.problem(inputs.t_ref, x0, inputs.drift), inputs)
        if self.mpc.qp is None:
            self.mpc.qp = self.mpc.build_qp(problem)
        build = time.perf_counter() - started
        qp = self.mpc.qp
        plan = qp.finish(qp.start(problem), qp.run())
        weights, reference = problem.state_weights, problem.state_reference
        gap = deviation(problem.initial_state, reference[0], weights)
        expected = deviation(plan.states[1], reference[1], weights)
        return _Built(plan, problem.contacts[0], build, qp.failures, problem, gap, expected)

    def _build_in_process(self, inputs: _BuildInputs) -> _Built:
        """:meth:`_build_and_run` in the solver process, its reply without the problem
        (a few hundred kB to send and read back) unless ``keeps_problems``."""
        built = self._build_and_run(inputs)
        return built if self.keeps_problems else built._replace(problem=None)

    def _shaped(self, problem: MpcProblem, inputs: _BuildInputs) -> MpcProblem:
        """``problem`` shaped by the rider's steps: coasting, the commanded roll, a
        re-push's blend, the turn, the crouch, the lean, the shoes' lines and drags and
        the swing's held forces."""
        names, t_ref, speed = self.layout.names, inputs.t_ref, inputs.speed
        if inputs.began:  # any new manoeuvre ends a re-push's blend (a re-push starts its own)
            self._blend = None
        # A re-push before its first push (while its blend runs) coasts too, its speeds
        # scaled to the board's: the entry's planned body speed, faster than a deck that
        # slows more than its model, had the MPC push the body forward and brake the deck.
        if inputs.coasting or self._blend is not None:
            problem = self.selector.coasting(problem, self.layout, speed)
        elif inputs.manoeuvre[0] == REPUSH:  # from the first push: the planned gain
            problem = shifted_speeds(problem, self.layout, speed)
        balance = None
        if self.selector.commands_roll(names, inputs.roll):
            balance = self.mpc.static_shift(t_ref, names["board_roll"], self.layout.rider_states)
        problem = self.selector.with_command(problem, names, inputs.roll, balance)
        if inputs.switched:
            self._blend = SwitchBlend.at_switch(problem, self.mpc.reference, self.layout, t_ref)
        if self._blend is not None:
            problem = self._blend(problem, t_ref)
            self._blend = None if self._blend.done(t_ref) else self._blend
        problem = self.selector.with_turn(problem, self.layout, inputs.turn, inputs.turned)
        if self.crouch is not None:
            problem = self.crouch.lower(problem, names["com_z"], inputs.now)
        lean = inputs.lean
        if lean is not None:
            if lean.offset != 0.0:
                balance = self._lean_balance(t_ref, inputs.manoeuvre)
                problem = lean.lean(problem, names["com_y"], names["vy"], balance)
            problem = lean.turn(problem, self.layout)
        if inputs.shoes is not None:  # each shoe's heading turned towards its line, its
            columns = self._shoe_columns  # feet's place along it and its drag
            states = spread_lines(problem.state_reference, columns, inputs.lateral_offset)
            if self._guidance:
                states = steer_onto_lines(states, problem.initial_state, columns)
            states = inputs.shoes.shift_reference(states, columns)
            c = inputs.shoes.speed_drift(problem.c, problem.dt, [v for *_, v in columns])
            problem = replace(problem, state_reference=states, c=c)
        return self._held_forces(problem, inputs.first_input, inputs.contacts)

    def _absorb_payload(self, estimate: EstimatedState, balancing: bool) -> None:
        """The payload estimated over the last MPC step (:mod:`~ridempc.mpc.payload`) while
        balancing (holding or coasting; held through a manoeuvre, whose accelerations move
        the centre of pressure off the centre of mass) put into the models the map and the
        whole-body QP read."""
        if self.payload is None:
            return
        if not balancing:
            self.payload.reset()
        payload = self.payload.update(estimate.q, self.map.com(estimate))
        for joint, inertia in enumerate(payload.inertias(self.payload.nominal_inertias)):
            self.pinocchio.model.inertias[joint] = inertia
            self.wbc.model.model.inertias[joint] = inertia
        self._diagnostics.update(payload_kg=payload.mass)

    def _adopt_pending(self) -> None:
        """The pending solve's plan taken up, once its tick has come (waiting for it if
        the solver is still at it)."""
        solve, self._pending = self._pending, None
        assert solve is not None and solve.reply is not None
        started = time.perf_counter()
        self._adopt(solve, solve.reply.result())
        self._mpc_main_s += time.perf_counter() - started

    def _adopt(self, solve: _PendingSolve, built: _Built) -> None:
        """The plan of ``solve`` (its problem ``built`` and solved) in force from this tick
        on, timed from the state it was solved from."""
        plan = built.plan
        self._contacts, self._last_problem = built.contacts, built.problem
        self._mpc_failures = built.failures
        self._deviation = built.deviation
        self._diagnostics["mpc_deviation"] = built.deviation
        riding = not self.handover.on_backup  # the peak is the MPC's own rides'
        self._divergence.update(solve.time, built.deviation, self._com_height, riding)
        self._divergence.expect(built.expected)
        if riding:
            settled = not plan.fallback and built.deviation <= RETURN_DEVIATION
            self._probation.update(solve.time, settled, RETURN_DWELL_S)
        else:
            self._probation.restart()
        if self.readiness is not None and self.handover.starting:
            in_band = not plan.fallback and built.deviation <= RETURN_DEVIATION
            settling = self.payload.estimate.settling() if self.payload is not None else None
            # a stop is the selector's ride-out of a push, which the backup rides too
            commanded = self.manoeuvre.kind not in (HOLD, "stop")
            self.readiness.update(solve.time, settling, in_band, commanded)
        warming = not self._probation.proven and solve.time < STANDBY_WARMUP_S
        settled = max(built.deviation, self._divergence.value) <= RETURN_DEVIATION
        self.handover.standby_every = standby_every(self._standby_every, warming, settled)
        self._mpc_ms.append(1e3 * (built.build_s + plan.solve_time))
        self._mpc_qp_ms.append(1e3 * plan.solve_time)
        if not np.all(np.isfinite(plan.states)):
            raise RidempcError(f"MPC plan not finite (status {plan.status})")
        if self.force_filter is not None:
            plan = plan._replace(first_input=self.force_filter(plan.first_input, solve.time))
        self._plan, self._plan_time, self._plan_frame = plan, solve.time, solve.frame
        self._set_support(built.contacts)
        self._diagnostics.update(
            mpc_ms=self._mpc_ms[-1],
            mpc_fallback=float(plan.fallback),
            mpc_iterations=float(plan.iterations),
        )

    def _lean_balance(self, t_ref: float, manoeuvre: tuple[str, float]) -> StaticShift:
        """How the reference's forces move per metre of the lean's offset, found once per
        manoeuvre at its first lean (the stance does not change over a speed change on
        the Segway; found at every tick of a ramp, where the reference moves, it took
        1.2 ms of the MPC tick)."""
        key = manoeuvre  # (kind, target)
        if self._lean_shift is None or self._lean_shift[0] != key:
            names, rider = self.layout.names, self.layout.rider_states
            self._lean_shift = (key, self.mpc.static_shift(t_ref, names["com_y"], rider))
        return self._lean_shift[1]

    def _held_forces(
        self, problem: MpcProblem, first_input: Array | None, last: tuple[Contact, ...]
    ) -> MpcProblem:
        """While a foot swings and no contact changes from the last tick (``last``), the
        first step's deck forces drawn to the last plan's (its ``first_input``;
        :mod:`~ridempc.mpc.input_rate`), with the pair's tolerance
        :attr:`~ridempc.mpc.pairs.MpcPair.swing_force_step`."""
        step, contacts = self.pair.swing_force_step, problem.contacts[0]
        if step is None or first_input is None or Contact.SWING not in contacts or last != contacts:
            return problem
        index = self.mpc.reference.force_index
        weights = np.zeros(problem.nu)
        for i, contact in enumerate(contacts):
            if contact is Contact.BOARD:
                weights[index[i]] = 1.0 / step**2
        return hold_first_input(problem, first_input, weights)

    def _roll_drift(
        self, x0: Array, now: float, balancing: bool, estimate: EstimatedState
    ) -> Array | None:
        """The deck's estimated disturbance torque as a drift of the MPC's rates
        (:mod:`~ridempc.mpc.roll_observer`), in four-leg balancing (holding before a
        push-off, or coasting after one); None elsewhere, or without a deck roll. Held,
        not integrated, while the feet of one side are off the deck or both planned at
        the least force: two feet on one fore-aft line do not see the deck's roll (push-off-1.0
        seed 5 read 0.002 rad of a 0.07-0.08 rad roll, and the estimate wound up to -5 N m
        in 0.5 s)."""
        observer = self.roll_observer
        if observer is None:
            return None
        if not balancing:
            observer.reset()
            return None
        share = (now - self._plan_time) / self.mpc.settings.dt
        hold = self._one_side_light(estimate)
        self._diagnostics["roll_disturbance"] = observer.update(x0, self._plan, share, hold)
        return observer.drift(len(x0))

    def _least_force(self) -> float:
        """The MPC's least force of a foot on the deck [N]."""
        count = len(self.mpc.reference.force_index)
        return self.mpc.reference.min_board_share * self.pair.weight / count

    def _one_side_light(self, estimate: EstimatedState) -> bool:
        """Whether both feet of one side (left or right of the deck's centre line, by their
        estimated places) are off the deck or planned within 1 N of the least force."""
        board, plan = estimate.board, self._plan
        side, index = self._side_feet, self.mpc.reference.force_index
        if board is None or plan is None or not side:
            return False
        if len(estimate.foot_position) != 2 * side or len(index) != 2 * side:
            return False
        contact = np.asarray(estimate.contact, dtype=bool)
        light = ~contact | (plan.first_input[index[:, 2]] <= self._least_force() + 1.0)
        across = _to_deck(board.yaw, estimate.foot_position[:, :2])[:, 1]
        order = np.argsort(across)
        return bool(light[order[:side]].all() or light[order[side:]].all())

    def _stance_roll(
        self, roll: Array, estimate: EstimatedState, now: float, balancing: bool
    ) -> Array:
        """The commanded deck roll held within what the stance can hold
        (:mod:`~ridempc.mpc.stance`), in four-leg balancing, from the four feet's estimated
        places (the last bounds while one is off the deck); as commanded elsewhere."""
        limit, board = self.stance, estimate.board
        if limit is None or board is None:
            return roll
        if not balancing:
            limit.reset()
            return roll
        feet = np.asarray(estimate.foot_position, dtype=float)
        four = bool(self._side_feet) and len(feet) == 2 * self._side_feet
        if not four or not np.all(estimate.contact) or self._plan is None:
            return np.clip(roll, *limit.last)
        com = self.map.com(estimate)
        centre = feet[:, :2].mean(axis=0)
        places = _to_deck(board.yaw, feet[:, :2] - centre)
        offset = _to_deck(board.yaw, com[:2] - centre)
        far_share = 2.0 * self._least_force() / self.pair.weight
        dt = now - self._plan_time
        low, high = limit.bounds(places, offset, float(board.roll), dt, far_share)
        self._diagnostics.update(stance_low=low, stance_high=high)
        return np.clip(roll, low, high)

    def _unwrapped(self, x0: Array, reference: Array) -> Array:
        """``x0`` with each heading (the base's yaw, the platforms') [rad] within
        :math:`\\pi` of the ``reference`` state's turned by the turn so far: the estimate's
        angles wrap at :math:`\\pm\\pi`, the commanded turn does not."""
        out = x0.copy()
        for i in self.layout.headings:
            target = reference[i] + self._turned
            out[i] = target + math.remainder(x0[i] - target, 2.0 * math.pi)
        return out

    def _coasting(self, t_ref: float) -> bool:
        """Whether the rider coasts (:meth:`ManoeuvreSelector.coasting`): past the end of
        an ``accelerate`` on a board it drives only by pushing off."""
        return (
            self.selector.coasts
            and self.manoeuvre.kind in ("accelerate", REPUSH)
            and t_ref >= float(self.mpc.reference.times[-1])
        )

    def _follow_board(
        self,
        estimate: EstimatedState,
        reference: Array,
        turn: Array,
        now: float,
        coasting: bool,
        yaw_rate: float,
    ) -> None:
        """Integrate the commanded turn and move the library frame onto the board (the
        ``reference`` state of this tick): across the reference's line (turned by the turn
        so far), along it by what lies beyond :data:`~ridempc.mpc.state_map.ALONG_SLACK`,
        and all along it while turning or coasting (the reference's steady ride is not
        where a coasting board goes); on a board whose heading the frame follows, that
        heading carried by ``yaw_rate`` [rad/s], the turn the rider is making."""
        if self._turn_time is not None:
            self._turned += self._turn_rate * (now - self._turn_time)
        self._turn_time, self._turn_rate = now, float(turn[0])
        x, y, heading = self.layout.board_pose(reference)
        along = coasting or bool(np.any(turn)) or self._turned != 0.0
        self.map.follow_sideways(
            estimate,
            (x, y, heading + self._turned),
            along=along,
            heading=self._follows_heading,
            yaw_rate=yaw_rate,
        )
        self.map.follow_ground(estimate)

    def _set_support(self, contacts: tuple[Contact, ...]) -> None:
        """Where each foot is over this MPC step, from the schedule's contacts: on the ground
        if any of its contacts is, in the air if all swing, else on its board. The
        estimator is told which feet stand on the ground and which swing (they say nothing
        of the board)."""
        feet = self.robot.params.foot_bodies
        support = [Contact.SWING] * len(feet)
        for contact, foot in zip(contacts, self._contact_foot, strict=True):
            if contact is Contact.GROUND or support[foot] is Contact.GROUND:
                support[foot] = Contact.GROUND
            elif contact is Contact.BOARD:
                support[foot] = Contact.BOARD
        self._support = tuple(support)
        ground = [f for f, c in zip(feet, support, strict=True) if c is Contact.GROUND]
        swinging = [f for f, c in zip(feet, support, strict=True) if c is Contact.SWING]
        self.estimator.set_support(ground, swinging)

    def _roll_horizon(self, command: Command, now: float) -> Array:
        """The commanded deck roll at the horizon's nodes [rad], each read the pair's
        ``roll_lead`` ahead (the closed loop's lag): from the ``command_preview`` when the
        ride's commands are planned, else the present command extrapolated at its rate (a
        backward difference over the last MPC step), which tracks a moving command one
        step late."""
        settings = self.mpc.settings
        times = now + self.pair.roll_lead + settings.dt * np.arange(settings.horizon + 1)
        planned = self._planned("roll", times)
        if planned is not None:
            return planned
        previous = self._command_roll
        self._command_roll = (now, command.roll)
        rate = 0.0
        if previous is not None and now > previous[0]:
            rate = (command.roll - previous[1]) / (now - previous[0])
        return np.asarray(command.roll + rate * (times - now), dtype=float)

    def _steering_roll(self, command: Command, now: float, speed: float) -> Array:
        """The deck roll that steers the commanded yaw rate at the horizon's nodes [rad]
        (:class:`~ridempc.boards.skateboard.steering.RollSteering`, at the board's speed
        :math:`v` [m/s]), each read the pair's ``roll_lead`` ahead as the commanded roll
        is; zero on a board that does not steer by its roll."""
        settings = self.mpc.settings
        if self.roll_steering is None:
            return np.zeros(settings.horizon + 1)
        times = now + self.pair.roll_lead + settings.dt * np.arange(settings.horizon + 1)
        rates = self._planned("yaw_rate", times)
        if rates is None:
            rates = np.full(len(times), float(command.yaw_rate))
        return np.array([self.roll_steering.roll(float(w), speed) for w in rates])

    def _roll_turn(self, roll: Array, speed: float) -> Array:
        """The turn a commanded deck roll steers, over the horizon's steps [rad/s]: on the
        skateboard eq. (14), :math:`\\omega_k = -v \\sin\\varphi^*_k / K_{board}` at the
        board's speed :math:`v` (the deck's roll is how it steers); zero elsewhere or
        without a roll command. Held on the reference's heading instead, a rolled deck
        rolling at 0.5 m/s fought the heading, reached half its commanded roll and then
        twice it the other way (push-off-1.0 fell at 10.7 s in its roll phase)."""
        steps = self.mpc.settings.horizon
        if self._steer_gain is None or not self.selector.commands_roll(self.layout.names, roll):
            return np.zeros(steps)
        return np.asarray(yaw_rate(speed, roll[:steps], self._steer_gain), dtype=float)

    def _yaw_rate_horizon(self, command: Command, now: float) -> Array:
        """The commanded yaw rate over the horizon's steps [rad/s], read ahead from the
        ``command_preview`` when the ride's commands are planned, else the present one."""
        settings = self.mpc.settings
        if not self.steers:
            return np.zeros(settings.horizon)
        planned = self._planned("yaw_rate", now + settings.dt * np.arange(settings.horizon))
        if planned is not None:
            return planned
        return np.full(settings.horizon, float(command.yaw_rate))

    def _yaw_rate_ahead(self, command: Command, now: float, window: tuple[float, float]) -> float:
        """The commanded yaw rate [rad/s] averaged over ``window`` [s] from ``now``: as a
        path follower expects to ask it (``turn_preview``), else where the ride's commands
        are planned, else the present one."""
        dt = self.mpc.settings.dt
        times = now + window[0] + dt * np.arange(max(1, round((window[1] - window[0]) / dt)))
        if self.turn_preview is not None:
            return float(np.mean([self.turn_preview(float(t)) for t in times]))
        planned = self._planned("yaw_rate", times)
        return float(np.mean(planned)) if planned is not None else float(command.yaw_rate)

    def _speed_preview_s(self) -> float:
        """How far ahead the manoeuvre reads a planned speed [s]: the MPC's horizon where the
        pair previews it and the ride's commands are planned, else 0
        (:attr:`~ridempc.mpc.pairs.MpcPair.speed_preview`)."""
        if not self.pair.speed_preview or self.command_preview is None:
            return 0.0
        return self.mpc.settings.horizon * self.mpc.settings.dt

    def _speed_command(self, command: Command, now: float) -> Command:
        """``command`` with the speed planned ``_speed_preview_s`` ahead."""
        lead = self._speed_preview_s()
        if lead == 0.0:
            return command
        assert self.command_preview is not None
        ahead = self.command_preview(now + lead).velocity
        if ahead == command.velocity:
            return command
        return command.model_copy(update={"velocity": ahead})

    def _planned(self, field: str, times: NDArray[np.floating[Any]]) -> Array | None:
        """One field of the ride's planned commands at ``times`` [s] (``command_preview``),
        or None when the commands are not planned ahead."""
        if self.command_preview is None:
            return None
        timeline = getattr(self.command_preview, "__self__", None)
        if isinstance(timeline, Scenario):  # the scenario's own: all the times in one call
            return timeline.command_field_at(field, times)
        return np.array([getattr(self.command_preview(float(t)), field) for t in times])

    def _speed(self, estimate: EstimatedState) -> float:
        if estimate.boards:
            return forward_speed(estimate.boards[0])
        return float(np.linalg.norm(estimate.base_velocity[:2]))

    def _wbc_tick(self, estimate: EstimatedState, now: float) -> MotorCommand:
        plan = self._plan
        assert plan is not None
        wanted = self._read_plan(plan, self._plan_frame, (now - self._plan_time) * 30.0)
        frame = self._plan_frame
        assert self._support is not None  # set by the MPC tick, which runs first
        contact = np.array([c is not Contact.SWING for c in self._support])
        swing = swing_velocity = posture = None
        if self.feet.plans_feet:  # the reference's feet and joint angles
            t_ref = self.manoeuvre.reference_time(now)
            states = self.mpc.reference.states_at(np.array([t_ref, t_ref + VELOCITY_STEP]))
            posture = self.feet.joint_angles(states[0], self.wbc.motor_q)
            if not contact.all():
                board = estimate.boards[0] if estimate.boards else None
                swing, swing_velocity = self.feet.targets(states, frame, board)
        elif not contact.all():  # without planned feet, a lifted foot holds where it is
            swing = self.wbc.model.foot_points(estimate.q)
        if not contact.any():
            contact[:] = True
        targets = WbcTargets(
            position=wanted.position,
            orientation=wanted.orientation,
            contact=contact,
            forces=wanted.forces,
            velocity=wanted.velocity,
            acceleration=wanted.acceleration,
            angular_velocity=wanted.angular_velocity,
            angular_acceleration=wanted.angular_acceleration,
            site_forces=wanted.site_forces if self._sites_match else None,
            swing_position=swing,
            swing_velocity=swing_velocity,
            posture=posture,
            board_acceleration=self.shoes.drift(estimate.boards) if self.shoes is not None else (),
        )
        out = self.wbc.solve(estimate, targets)
        self._contact_force = out.forces.sum(axis=0)
        self._com_velocity = out.com_velocity
        if self.shoes is not None:
            self.shoes.update(estimate, out.site_positions, out.site_forces)
        self._wbc_ms.append(out.model_ms + out.build_ms + out.solve_ms)
        slack = self.wbc.last_solution.slack if self.wbc.last_solution is not None else 0.0
        self._wbc_slack_max = max(self._wbc_slack_max, slack)
        self._diagnostics.update(wbc_ms=self._wbc_ms[-1], wbc_slack=slack)
        return to_motor_command(out, self.kp, self.kd, torque=self.torque_lead(now, out.torque))

    # ------------------------------------------------------------------ reports

    def estimate(self) -> EstimatedState | None:
        return self.estimator.state

    def diagnostics(self) -> dict[str, float]:
        return dict(self._diagnostics)

    @property
    def mpc_tick_ms(self) -> tuple[float, ...]:
        """Each MPC tick's time so far [ms]: building the problem and solving it (the
        solve's own time, not the ticks it runs alongside)."""
        return tuple(self._mpc_ms)

    @property
    def mpc_loop_seconds(self) -> float:
        """The MPC's time in the control loop's thread so far [s]: building, starting and
        finishing its solves, and waiting for one still running when its tick comes."""
        return self._mpc_main_s

    def summary(self) -> dict[str, Any]:
        """Solve times, fallbacks and the safe hold, for ``summary.json``: the MPC's QP
        (``mpc_solve_ms``: its update and OSQP's solve, as ``ridempc bench`` times it) and
        its whole tick (``mpc_tick_ms``: building the problem too), median and p99 [ms]."""
        out: dict[str, Any] = {}
        for key, values in (
            ("mpc_solve_ms", self._mpc_qp_ms),
            ("mpc_tick_ms", self._mpc_ms),
            ("wbc_solve_ms", self._wbc_ms),
        ):
            if values:
                ms = np.asarray(values)
                out[key] = {"median": float(np.median(ms)), "p99": float(np.percentile(ms, 99))}
        out["mpc_solves"] = len(self._mpc_ms)
        out["speed_preview_s"] = self._speed_preview_s()
        out["mpc_fallbacks"] = self._mpc_failures
        out["wbc_failures"] = self._wbc_failures
        out["wbc_cold_retries"] = self.wbc.qp.cold_retries
        out["wbc_daqp_solves"] = self.wbc.qp.fallbacks
        out["wbc_elastic_solves"] = self.wbc.qp.elastic_solves
        out["wbc_slack_max"] = self._wbc_slack_max
        out["fallbacks"] = self.handover.summary()
        out["mpc_takeover_s"] = 0.0 if self.readiness is None else self.handover.takeover_s
        if self.readiness is not None:
            out["takeover"] = self.readiness.summary()
        out["deviation_divergent_max"] = self._divergence.peak
        out["impulse_max"] = self.impulse.peak if self.impulse is not None else None
        out["impulse_max_time_s"] = self.impulse.peak_time if self.impulse is not None else None
        out["safe_hold"] = (
            None
            if self._hold_reason is None
            else {"time_s": self._hold_time, "reason": self._hold_reason}
        )
        return out
