"""``mpc``: the skateboard paper's pipeline (section V) riding any pair with an MPC library.

The rider is a loop over stages, each of one protocol (:mod:`ridempc.mpc.stages.base`),
built once from the pair file's ``[stages.*]`` (``pairs/<robot>-<board>.toml``) and listed,
in the order they act, in one place, :meth:`MpcRider._build_stages` (``observers``,
``wbc_observers``, ``drifts``, ``shapers``, ``triggers``). Every 2 ms (500 Hz) the rider

1. estimates its state from the sensors (:class:`~ridempc.estimation.StateEstimator`, the
   board from its own feet), each shoe's heading from its direction of travel
   (:mod:`~ridempc.mpc.shoe_heading`), and updates the **tick observers** (the platforms
   falling away, :class:`~ridempc.mpc.stages.triggers.DropWatch`, and the drop's flight,
   :class:`~ridempc.mpc.flight.DropFlight`; the stance's loads for the payload,
   :mod:`~ridempc.mpc.stages.payload_models`);
2. every 15th tick (30 Hz), chooses the manoeuvre the command asks for
   (:mod:`~ridempc.mpc.stages.manoeuvre_choice`: a push-off or a speed change follows its
   library trajectory, then rides on; on the skateboard it coasts and pushes again), reads the
   commands over the horizon (the command source,
   :class:`~ridempc.mpc.stages.commands.CommandHorizon`; on the skateboard a yaw rate
   steered by the deck's roll, within what the stance holds,
   :class:`~ridempc.mpc.stages.deck_roll.StanceRoll`), maps the estimate into the library
   frame (:class:`~ridempc.mpc.state_map.StateMap`, which follows the board sideways onto
   the reference's line, and on the Segway turns with its direction of travel), sums the
   **drift sources** (disturbance observers: the deck's torque, the payload, the steady
   disturbance, the lean's pull; :mod:`~ridempc.mpc.stages.deck_roll`,
   :mod:`~ridempc.mpc.stages.drifts`) into the MPC's rates, and builds the linear MPC's
   problem (:class:`~ridempc.mpc.controller.LinearMpc`) shaped by the **problem shapers**
   in order (:mod:`~ridempc.mpc.stages.manoeuvre_shapers`: coasting, the commanded roll, a
   re-push's blend, the turn; :mod:`~ridempc.mpc.stages.board_shapers`: the Segway's crouch
   and lean, the Hovershoes' lines and drags, the swing's held forces). It is solved in the
   tick, the solver thread or a process of its own (``off_tick``), from the state
   predicted at the plan's take-up ``plan_latency`` ticks later (:mod:`ridempc.mpc.delay`;
   else the tick's, its time shifted: the pair's ``predict_start``), waited for then
   whatever the machine, the ticks between following the previous plan in its own frame;
3. turns the plan into whole-body targets (:class:`~ridempc.mpc.plan_targets.PlanReader`:
   the plan interpolated over the 1/30 s step, its first input's forces, low-passed on the
   Hovershoes, :mod:`~ridempc.mpc.force_filter`; the feet's support and swing,
   :mod:`~ridempc.mpc.stages.feet_targets`; each shoe's drag as its platform's
   acceleration) and solves the 500 Hz whole-body QP
   (:class:`~ridempc.wbc.WholeBodyController`, :mod:`ridempc.mpc.rider_wbc`);
4. updates the observers of the QP's output (the shoes' observer, the push's watch), asks
   the **handover triggers** in order (:mod:`~ridempc.mpc.stages.triggers`) why the MPC
   cannot ride, and sends the QP's torques as feedforward, each led over its motor's
   torque delay (:mod:`~ridempc.wbc.torque_lead`), with its joint targets to the motor PD
   (:func:`~ridempc.mpc.rider_wbc.tracking_gains`).

**Fallback.** The whole-body QP always returns a command (slack on its soft rows,
:mod:`ridempc.wbc.elastic`). If the MPC's QP fails (its previous plan shifted by one step is
then used), anything raises, the estimate is not finite, or a trigger gives a reason, the
ride is handed to the pair's PD baseline (:data:`BACKUP_LAW`, in standby beside the MPC,
reading the rider's estimate), the motor commands blended, and handed back once the MPC's
plans have solved and its state has stayed near the reference for a while
(:mod:`~ridempc.mpc.handover`); each handover is in ``summary()``'s ``fallbacks``. With the
pair's ``takeover`` stage the ride starts on that backup, the MPC planning beside it, and
the MPC takes over once ready (:mod:`~ridempc.mpc.readiness`; ``summary()``'s
``mpc_takeover_s``). Only where the backup too has no finite command are the joints held
where they are (``safe_hold``).

**Towards a few hundred lines.** What is left here beyond the loop: the commanded roll's
and turn's composition and the library frame's turn in :meth:`MpcRider._mpc_tick` (the
command source's), the solve's dispatch to the tick, thread or process (:meth:`MpcRider._submit`,
:meth:`MpcRider._build_and_run`: a solver stage beside :mod:`~ridempc.mpc.solver_process`),
the handover's bookkeeping at a plan's take-up (:meth:`MpcRider._adopt`: divergence,
probation, readiness, the backup's standby; an *observer* of the plans) and the wiring of
the remaining stages in ``__init__`` (a factory per stage, read from the pair file).
"""

from __future__ import annotations

import copy
import math
import time
from concurrent.futures import Future
from functools import cache, partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.canonical import board_state_columns
from ridempc.controllers.base import Controller
from ridempc.errors import RidempcError
from ridempc.estimation import EstimatedState, StateEstimator
from ridempc.mpc.controller import LinearMpc, MpcSettings
from ridempc.mpc.delay import predicted_start
from ridempc.mpc.divergence import DivergentDeviation, Probation
from ridempc.mpc.drop import DropDetector
from ridempc.mpc.flight import DropFlight
from ridempc.mpc.foot_spread import spread_lines
from ridempc.mpc.force_filter import ForceFilter
from ridempc.mpc.handover import (
    RETURN_DEVIATION,
    RETURN_DWELL_S,
    STANDBY_DIVIDER,
    Handover,
    deviation,
    share_estimator,
    standby_every,
)
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
from ridempc.mpc.platform_feet import platform_feet, rolling_platforms
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.push_handover import deviation_deferred
from ridempc.mpc.push_side import PushSide
from ridempc.mpc.readiness import start_readiness
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.rider_wbc import rider_wbc, tracking_gains
from ridempc.mpc.solver_process import Reply, SolverProcess, forks
from ridempc.mpc.solver_thread import SolverThread
from ridempc.mpc.stages.base import (
    ControlTick,
    DriftSource,
    MpcTick,
    ProblemShaper,
    TickObserver,
    present,
)
from ridempc.mpc.stages.board_shapers import CrouchShaper, HeldForces, LeanShaper
from ridempc.mpc.stages.build import BuildInputs, Built, PendingSolve
from ridempc.mpc.stages.commands import CommandHorizon
from ridempc.mpc.stages.deck_roll import deck_stages
from ridempc.mpc.stages.drifts import LeanDrift, SteadyDrift, disturbance_observer
from ridempc.mpc.stages.feet_targets import FeetTargets
from ridempc.mpc.stages.manoeuvre_choice import ManoeuvreChoice
from ridempc.mpc.stages.manoeuvre_shapers import Coasting, RepushBlend, RollCommand, Turn
from ridempc.mpc.stages.payload_models import PayloadModels
from ridempc.mpc.stages.shoes import ShoeUpdate, shoe_stages
from ridempc.mpc.stages.support import contacts_to_feet, foot_support
from ridempc.mpc.stages.triggers import DropWatch, HandoverCheck, PushWatch, handover_triggers
from ridempc.mpc.stages.turn import TurnSoFar
from ridempc.mpc.stagger import standby_phase
from ridempc.mpc.state_map import GROUND_FILTER_S, PlanarFrame, StateMap, forward_speed
from ridempc.mpc.swing import ReferenceFeet
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket
from ridempc.trajopt.schedule import Contact
from ridempc.wbc import WbcTargets, to_motor_command
from ridempc.wbc.qp import WbcFailed
from ridempc.wbc.targets import WbcOutput
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
        # offset-free MPC (mpc/disturbance.py)
        self.disturbance = disturbance_observer(self.pair, self.mpc.reference.state_names)
        self.manoeuvre: Manoeuvre = first
        reference = self.mpc.reference
        self.layout = StateLayout.from_pair(reference.state_names, self.pair)
        ground = self.pair.description.mpc.ground_rate_filter  # its rise rate's lag [s]
        self.map = StateMap(
            self.pinocchio,
            reference.state_names,
            self.pair.board_states,
            base=self.pair.base,
            ground_rate_filter=GROUND_FILTER_S if ground is None else ground,
        )
        self.wbc = rider_wbc(robot, board, loaded, self.pinocchio, self.pair, wbc_solver)
        self._feedforward = tuning.feedforward
        tau = self.pair.force_time_constant  # the forces the WBC gets, low-passed
        self.force_filter = ForceFilter(tau) if tau is not None else None
        self.kp, self.kd = tracking_gains(robot, board, tuning.tracking_gain_scale)
        self.torque_lead = TorqueLead(robot, self.wbc.settings.dt)  # sent ahead of the delay
        feet = robot.params.foot_bodies  # the foot of each library contact
        self._contact_foot = contacts_to_feet(robot.mj_model, feet, reference.contact_names)
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
        # where each foot stands along its shoe and each shoe's drag, its heading (Hovershoes)
        shoes = shoe_stages(stages, loaded, self.wbc.model, self.platform_feet, columns)
        self.shoes, self.shoe_heading, self._shoe_lines, self._shoe_columns = shoes
        n_feet = len(robot.params.foot_bodies)  # the deck's roll steering and balance
        deck = deck_stages(self.pair, loaded, columns, self.mpc, n_feet, self.map.com)
        self.commands = CommandHorizon(  # the commands read over the horizon
            self,
            self.mpc.settings,
            self.pair.roll_lead,
            self.steers,
            deck.steer_gain,
            self.pair.speed_preview,
        )
        self.choice = ManoeuvreChoice(  # the manoeuvre the command asks for
            self.selector, self.mpc, self.layout, self.pair, self.push_side, self.commands
        )
        self.roll_drift, self.stance_roll = deck.drift, deck.stance
        self.feet = ReferenceFeet(
            self.wbc.model, reference.state_names, self.layout.base_prefix, self.layout.board_pose
        )
        self.feet_targets = FeetTargets(self.feet, self.wbc, self.mpc)
        self._support: tuple[Contact, ...] | None = None  # per foot, this MPC step
        self._contacts: tuple[Contact, ...] = ()  # per library contact, the last MPC step
        self._tick = 0
        self._plan: Plan | None = None
        self._plan_frame = PlanarFrame()
        self._last_problem: MpcProblem | None = None
        self._plan_time = 0.0
        self.turn = TurnSoFar()  # the commanded yaw rate integrated over the ride
        self._hold: MotorCommand | None = None
        self._wbc_failures = 0  # in all
        self._hold_reason: str | None = None
        self._hold_time: float | None = None
        self._mpc_ms: list[float] = []  # each tick: building the problem and solving it
        self._mpc_qp_ms: list[float] = []  # each tick's QP: updating it and solving it
        self._mpc_main_s = 0.0  # [s] the MPC's time in the control loop's own thread
        self._pending: PendingSolve | None = None
        self._worker: SolverProcess[BuildInputs, Built] | None = None
        self._sent_reference: MotionReference | None = None  # the last one the build got
        self._mpc_failures = 0  # the MPC's fallbacks, as of the last plan taken up
        self._wbc_ms: list[float] = []
        self._wbc_slack_max = 0.0  # the largest slack the WBC's soft rows took
        self._deviation = 0.0  # [-] the MPC's state from its reference (handover.deviation)
        self._divergence = DivergentDeviation()  # where that deviation is heading
        self._probation = Probation()  # whether the MPC has shown its model holds the rider
        # the platforms falling away under the feet (a step), with the ``drop`` stage
        self.drop_watch = DropWatch(DropDetector()) if stages.drop is not None else None
        # the drop ridden by the whole-body QP, the feet after the platforms (``flight``)
        self.flight = (
            DropFlight(self.drop_watch, stages.flight.extend_speed, stages.flight.max_extension)
            if stages.flight is not None
            else None
        )
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
        self.push_watch = PushWatch.of(stages.impulse, self.wbc.model.mass)
        self.impulse = self.push_watch.observer if self.push_watch is not None else None
        self.payload_models = (
            PayloadModels(
                self.payload,
                (self.pinocchio.model, self.wbc.model.model),
                self.map.com,
                self.layout.names["vz"],
            )
            if self.payload is not None
            else None
        )
        self._build_stages()

    def _build_stages(self) -> None:
        """Every list of stages, each in the order its stages act (one protocol a list,
        :mod:`ridempc.mpc.stages.base`): where a new stage is added."""
        shoes = ShoeUpdate(self.shoes) if self.shoes is not None else None
        self.observers: tuple[TickObserver, ...] = present(
            self.drop_watch, self.flight, self.payload_models
        )
        self.wbc_observers: tuple[TickObserver, ...] = present(shoes, self.push_watch)
        self.drifts: tuple[DriftSource, ...] = self._drift_sources()
        self.shapers: tuple[ProblemShaper, ...] = self._problem_shapers()
        self.triggers = handover_triggers(self.drop_watch, self.push_watch, self.flight)

    def _drift_sources(self) -> tuple[DriftSource, ...]:
        """The disturbance observers whose drifts the MPC's rates carry, in the order they
        are summed: the deck's torque, the payload, the steady disturbance, the lean's."""
        dt, names = self.mpc.settings.dt, self.layout.names
        return present(
            self.roll_drift,
            self.payload_models,
            SteadyDrift(self.disturbance, dt) if self.disturbance is not None else None,
            LeanDrift(self.lean, names["vy"]) if self.lean is not None else None,
        )

    def _problem_shapers(self) -> tuple[ProblemShaper, ...]:
        """The problem shapers, in the order they act: the manoeuvre's (coasting, the
        commanded roll, a re-push's blend, the turn), then the board's (the crouch, the
        lean, the shoes' lines and drags, the swing's held forces)."""
        mpc, layout, step = self.mpc, self.layout, self.pair.swing_force_step
        blend = RepushBlend(mpc, layout)
        return present(
            Coasting(layout, blend),
            RollCommand(mpc, layout),
            blend,
            Turn(layout),
            CrouchShaper(self.crouch, layout.names["com_z"]) if self.crouch is not None else None,
            LeanShaper(mpc, layout) if self.lean is not None else None,
            self._shoe_lines,
            HeldForces(mpc, step) if step is not None else None,
        )

    def _mapped(self, estimate: EstimatedState) -> EstimatedState:
        """The estimate as the MPC sees it: each Hovershoe's origin on its axis."""
        return estimate if self.shoes is None else self.shoes.shift(estimate)

    # ------------------------------------------------------------------ loop

    def reset(self, sensors: SensorPacket) -> None:
        self.estimator.reset(sensors)
        self.map.reset()
        self.torque_lead.reset()
        if self.drop_watch is not None:
            self.drop_watch.reset()
        if self.flight is not None:
            self.flight.reset()
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
        if self.shoe_heading is not None:
            estimate = self.shoe_heading(estimate)
        loads, on_backup = self.estimator.contact.last_load, self.handover.on_backup
        tick = ControlTick(sensors, estimate, loads, on_backup, self._diagnostics)
        for observer in self.observers:
            observer.observe(tick)
        try:
            if self._tick % MPC_DIVIDER == 0:
                self._mpc_tick(estimate, command, sensors.time)
            if self._pending is not None and self._tick >= self._pending.due:
                self._adopt_pending()
            if self._plan is None:
                return None, "no MPC plan"
            out, solved = self._wbc_tick(estimate, sensors.time)
        except WbcFailed as exc:
            self._wbc_failures += 1
            return None, f"WbcFailed: {exc}"
        except RidempcError as exc:
            return None, f"{type(exc).__name__}: {exc}"
        tick = tick._replace(wbc=solved)
        for observer in self.wbc_observers:
            observer.observe(tick)
        repushing, start = self.manoeuvre.kind == REPUSH, self.manoeuvre.target - REPUSH_BAND
        stroke = deviation_deferred(repushing, self._support, self._speed(estimate), start)
        check = HandoverCheck(
            self._plan,
            self._diagnostics.get("wbc_slack", 0.0),
            self._deviation,
            stroke,
            self._probation.proven,
            self._divergence,
        )
        for trigger in self.triggers:  # the first reason hands the ride over
            reason = trigger(check)
            if reason is not None:
                return out, reason
            if trigger is self.flight and self.flight.flying:  # the rest wait for the landing
                break
        return out, None

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
        rider_speed = self.map.rider_speed(estimate)  # the CoM's, as the reference's vx
        coasted = self._coasting(self.manoeuvre.reference_time(now))
        chosen = self.choice(self.manoeuvre, command, now, speed, rider_speed, coasted)
        began = chosen is not None
        if chosen is not None:
            self._divergence.reset()  # a new reference: its deviation steps, no divergence
            self.manoeuvre = chosen
            switched = chosen.kind == REPUSH  # from wherever the coast left the rider
            # any switch starts mid-turn: the reference's heading already carries the turn
            # made (anchored at the library's, a rider 0.2 rad into yaw-steps was asked to
            # turn back at once and fell in the push; one 0.67 rad into a course, in a stop)
            self._anchor(estimate, now, self.turn.turned)
        else:
            switched = False
            if self.handover.starting and self.manoeuvre.kind == HOLD:  # the frame on the
                self._anchor(estimate, now, self.turn.turned)  # board while the backup holds it
        t_ref = self.manoeuvre.reference_time(now)
        mapped = self._mapped(estimate)
        coasting = self._coasting(t_ref)
        balancing = self.manoeuvre.kind == HOLD or coasting
        held = self.handover.on_backup or self._pending is not None  # the plan not followed
        tick = MpcTick(
            estimate,
            now,
            speed,
            balancing,
            self._plan,
            self._plan_time,
            0.0,
            held,
            self._diagnostics,
        )
        if self.payload_models is not None:
            self.payload_models.absorb(tick)
        pushing = Contact.GROUND in self._contacts  # a foot on the ground goes straight
        steering = balancing or (self.manoeuvre.kind == REPUSH and not pushing)
        limit = partial(self.stance_roll, tick=tick) if self.stance_roll is not None else None
        names = self.layout.names
        roll, turn = self.commands.roll_and_turn(command, now, speed, steering, limit, names)
        here = self.mpc.reference.states_at(np.array([t_ref]))[0]  # the reference at t_ref
        if self.shoes is not None:  # the frame follows platform 0 onto its spread line
            here = spread_lines(here[None, :], self._shoe_columns, command.lateral_offset)[0]
        yaw_rate = estimate.yaw_rate
        if self.lean is not None:
            self.lean.update(now, command.yaw_rate, yaw_rate, speed)
        carried = self.lean.turn_rate if self.lean is not None else 0.0
        self._follow_board(mapped, here, turn, now, coasting, carried)
        x0 = self.turn.unwrapped(self.map.state(mapped), here, self.layout.headings)
        started = time.perf_counter()
        turned = math.remainder(self.map.frame.yaw - self._plan_frame.yaw, 2.0 * math.pi)
        tick = tick._replace(frame_turn=turned)  # the frame has moved onto the board
        drift: Array | None = None
        for source in self.drifts:  # the disturbance observers' drifts, summed in order
            more = source.drift(tick, x0)
            if more is not None:
                drift = more if drift is None else drift + more
        # the plan starts where it takes over (mpc/delay.py): the first plan is waited for
        late = self.plan_latency > 0 and self._plan is not None and self.predicts_start
        delay = self.plan_latency / self.rate_hz if late else 0.0
        inputs = BuildInputs(  # what the loop's state says now, copied: the build may run
            self.manoeuvre.reference_time(now + delay),  # beside the loop's next ticks,
            x0,
            drift,  # which move the shoes' observer on
            now + delay,
            speed,
            roll,
            turn,
            self.turn.turned,
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
        pending = PendingSolve(self.map.frame, now + delay, self._tick + self.plan_latency)
        if self.plan_latency == 0 or self._plan is None:  # the first plan is waited for
            self._adopt(pending, self._build_and_run(inputs))
        else:
            self._pending = pending._replace(reply=self._submit(inputs))
        self._mpc_main_s += time.perf_counter() - started

    def _submit(self, inputs: BuildInputs) -> Future[Built] | Reply[Built]:
        """The build and solve of ``inputs`` started where ``off_tick`` says."""
        where = self.off_tick
        process = where == "process" and self.plan_latency >= PROCESS_MIN_LATENCY
        if process and (self._worker is not None or forks()):
            if self._worker is None:
                self._worker = SolverProcess(self._build_in_process)
            return self._worker.submit(inputs)
        if where in ("process", "thread"):
            return _solver_thread().submit(partial(self._build_and_run, inputs))
        future: Future[Built] = Future()
        future.set_result(self._build_and_run(inputs))
        return future

    def close(self) -> None:
        """End the MPC's solver process, if one was started (at the end of a ride)."""
        if self._worker is not None:
            self._worker.close()
            self._worker = None

    def _build_and_run(self, inputs: BuildInputs) -> Built:
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
        return Built(plan, problem.contacts[0], build, qp.failures, problem, gap, expected)

    def _build_in_process(self, inputs: BuildInputs) -> Built:
        """:meth:`_build_and_run` in the solver process, its reply without the problem
        (a few hundred kB to send and read back) unless ``keeps_problems``."""
        built = self._build_and_run(inputs)
        return built if self.keeps_problems else built._replace(problem=None)

    def _shaped(self, problem: MpcProblem, inputs: BuildInputs) -> MpcProblem:
        """``problem`` shaped by the rider's problem shapers, in order (:attr:`shapers`)."""
        for shaper in self.shapers:
            problem = shaper(problem, inputs)
        return problem

    def _adopt_pending(self) -> None:
        """The pending solve's plan taken up, once its tick has come (waiting for it if
        the solver is still at it)."""
        solve, self._pending = self._pending, None
        assert solve is not None and solve.reply is not None
        started = time.perf_counter()
        self._adopt(solve, solve.reply.result())
        self._mpc_main_s += time.perf_counter() - started

    def _adopt(self, solve: PendingSolve, built: Built) -> None:
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
        in_return_band = max(built.deviation, self._divergence.value) <= RETURN_DEVIATION
        self.handover.standby_every = standby_every(self._standby_every, warming, in_return_band)
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
        turned = self.turn.advance(now, float(turn[0]))
        x, y, heading = self.layout.board_pose(reference)
        along = coasting or bool(np.any(turn)) or turned != 0.0
        self.map.follow_sideways(
            estimate,
            (x, y, heading + turned),
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
        support = foot_support(contacts, self._contact_foot, len(feet))
        self._support = support
        ground = [f for f, c in zip(feet, support, strict=True) if c is Contact.GROUND]
        swinging = [f for f, c in zip(feet, support, strict=True) if c is Contact.SWING]
        self.estimator.set_support(ground, swinging)

    def _speed(self, estimate: EstimatedState) -> float:
        if estimate.boards:
            return forward_speed(estimate.boards[0])
        return float(np.linalg.norm(estimate.base_velocity[:2]))

    def _wbc_tick(self, estimate: EstimatedState, now: float) -> tuple[MotorCommand, WbcOutput]:
        """The whole-body QP's motor command for the plan in force at ``now`` [s], and its
        output."""
        plan = self._plan
        assert plan is not None
        wanted = self._read_plan(plan, self._plan_frame, (now - self._plan_time) * 30.0)
        assert self._support is not None  # set by the MPC tick, which runs first
        t_ref = self.manoeuvre.reference_time(now)
        feet = self.feet_targets(self._support, t_ref, estimate, self._plan_frame)
        swing_acceleration = None
        if self.flight is not None and self.flight.flying:  # no foot stands: mpc/flight.py
            feet, swing_acceleration = self.flight.feet(feet, estimate)
        targets = WbcTargets(
            position=wanted.position,
            orientation=wanted.orientation,
            contact=feet.contact,
            forces=wanted.forces,
            velocity=wanted.velocity,
            acceleration=wanted.acceleration,
            angular_velocity=wanted.angular_velocity,
            angular_acceleration=wanted.angular_acceleration,
            site_forces=wanted.site_forces if self._sites_match else None,
            swing_position=feet.swing,
            swing_velocity=feet.swing_velocity,
            swing_acceleration=swing_acceleration,
            posture=feet.posture,
            board_acceleration=self.shoes.drift(estimate.boards) if self.shoes is not None else (),
        )
        out = self.wbc.solve(estimate, targets)
        self._wbc_ms.append(out.model_ms + out.build_ms + out.solve_ms)
        slack = self.wbc.last_solution.slack if self.wbc.last_solution is not None else 0.0
        self._wbc_slack_max = max(self._wbc_slack_max, slack)
        self._diagnostics.update(wbc_ms=self._wbc_ms[-1], wbc_slack=slack)
        torque = self.torque_lead(now, out.torque)
        return to_motor_command(out, self.kp, self.kd, torque=torque), out

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
        out["speed_preview_s"] = self.commands.speed_preview_s()
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
        out["flights_s"] = list(self.flight.starts) if self.flight is not None else None
        out["safe_hold"] = (
            None
            if self._hold_reason is None
            else {"time_s": self._hold_time, "reason": self._hold_reason}
        )
        return out
