"""The rider's parts, built from its pair file (:class:`RiderParts`, the base of
:class:`~ridempc.mpc.rider.MpcRider`).

Everything the rider's loop uses is built here once, in the order each part needs the
ones before it: the pair file (``pairs/<robot>-<board>.toml``, :mod:`ridempc.mpc.pairs`),
the estimator, the MPC over the pair's library, the library frame, the whole-body QP, each
stage the pair file names under ``[stages.*]`` (None where it does not), the backup law
and its handover. The stages are then listed by protocol (:mod:`ridempc.mpc.stages.base`),
each list in the order its stages act, in :meth:`RiderParts._build_stages`: where a new
stage is added.
"""

from __future__ import annotations

from ridempc.boards.canonical import board_state_columns
from ridempc.controllers.base import Controller
from ridempc.estimation import StateEstimator
from ridempc.mpc.controller import LinearMpc, MpcSettings
from ridempc.mpc.drop import DropDetector
from ridempc.mpc.flight import DropFlight
from ridempc.mpc.force_filter import ForceFilter
from ridempc.mpc.handover import RETURN_DWELL_S, STANDBY_DIVIDER, Handover, share_estimator
from ridempc.mpc.landing import LandingLoads
from ridempc.mpc.lean import Crouch, LeanSteering
from ridempc.mpc.manoeuvre import REPUSH, Manoeuvre, ManoeuvreSelector, StateLayout
from ridempc.mpc.pairs import check_library_names, load_mpc_pair
from ridempc.mpc.payload import PayloadEstimator
from ridempc.mpc.plan_book import PlanBook
from ridempc.mpc.plan_solver import PlanSolver
from ridempc.mpc.plan_targets import PlanReader
from ridempc.mpc.platform_feet import platform_feet
from ridempc.mpc.push_side import PushSide
from ridempc.mpc.readiness import start_readiness
from ridempc.mpc.reference import MotionReference
from ridempc.mpc.rider_wbc import rider_wbc, tracking_gains
from ridempc.mpc.slope_trim import SlopeTrim
from ridempc.mpc.solver_process import SolverProcess
from ridempc.mpc.stages.base import DriftSource, ProblemShaper, TickObserver, present
from ridempc.mpc.stages.board_shapers import CrouchShaper, HeldForces, LeanShaper
from ridempc.mpc.stages.build import BuildInputs, Built, PendingSolve, build_and_run
from ridempc.mpc.stages.commands import CommandHorizon
from ridempc.mpc.stages.deck_roll import deck_stages
from ridempc.mpc.stages.drifts import LeanDrift, SteadyDrift, disturbance_observer
from ridempc.mpc.stages.feet_targets import FeetTargets
from ridempc.mpc.stages.frame_follow import CommandedFrame
from ridempc.mpc.stages.manoeuvre_choice import ManoeuvreChoice
from ridempc.mpc.stages.manoeuvre_shapers import Coasting, RepushBlend, RollCommand, Turn
from ridempc.mpc.stages.payload_models import PayloadModels, start_weight, weighed
from ridempc.mpc.stages.plan_watch import PlanWatch
from ridempc.mpc.stages.shoes import ShoeUpdate, shoe_stages
from ridempc.mpc.stages.support import contacts_to_feet
from ridempc.mpc.stages.triggers import DropWatch, PushWatch, handover_triggers
from ridempc.mpc.stages.turn import TurnSoFar
from ridempc.mpc.stages.wbc_targets import TargetsFromPlan
from ridempc.mpc.stagger import standby_phase
from ridempc.mpc.state_map import GROUND_FILTER_S, StateMap
from ridempc.mpc.swing import ReferenceFeet
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.robots.robot import Robot
from ridempc.sim.motors import MotorCommand
from ridempc.trajopt.schedule import Contact
from ridempc.wbc.torque_lead import TorqueLead

__all__ = ["BACKUP_LAW", "MPC_DIVIDER", "RiderParts"]

MPC_DIVIDER: int = 15  # 500 Hz / 15 = 33.3 Hz ~ the paper's 30 Hz; the MPC step stays 1/30 s
# The law the ride is handed to when the MPC or its QP fails (ridempc.mpc.handover): the
# pair's PD baseline, which balances every pair from the same sensors.
BACKUP_LAW: str = "pd"


def _backup(robot: Robot, board: str) -> Controller:
    """The registry's :data:`BACKUP_LAW` for ``robot`` on ``board``."""
    from ridempc.controllers.registry import CONTROLLERS  # the registry imports the rider

    return CONTROLLERS[BACKUP_LAW](robot, board)


class RiderParts(Controller):
    """The MPC rider's parts for ``robot`` on ``board`` (arguments as
    :class:`~ridempc.mpc.rider.MpcRider`'s), and its stages listed by protocol."""

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
        hands_over_deviations: bool = True,
    ) -> None:
        super().__init__(robot, board)
        from ridempc.boards import load_board

        # Whether a push or a deviation from the reference hands the ride to the backup law
        # (False: only the MPC's own failures, the ``mpc-alone`` ablation).
        self.hands_over_deviations = hands_over_deviations

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
        self._slope_trim = self.shoes is not None and stages.slope_trim is not None
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
        self._tick = 0
        self.book = PlanBook(self.force_filter)  # the plan in force (mpc/plan_book.py)
        self.turn = TurnSoFar()  # the commanded yaw rate integrated over the ride
        self.commanded = CommandedFrame(  # the commanded roll and turn, the frame on the board
            self.commands,
            self.mpc,
            self.layout,
            self.map,
            self.turn,
            self.lean,
            self.stance_roll,
            self._shoe_columns if self.shoes is not None else None,
            self._follows_heading,
        )
        self._hold: MotorCommand | None = None
        self._wbc_failures = 0  # in all
        self._hold_reason: str | None = None
        self._hold_time: float | None = None
        self._mpc_main_s = 0.0  # [s] the MPC's time in the control loop's own thread
        self._sent_reference: MotionReference | None = None  # the last one the build got
        self._wbc_ms: list[float] = []
        self._wbc_slack_max = 0.0  # the largest slack the WBC's soft rows took
        # the platforms falling away under the feet (a step), with the ``drop`` stage
        self.drop_watch = DropWatch(DropDetector()) if stages.drop is not None else None
        # the drop ridden by the whole-body QP, the feet after the platforms (``flight``)
        self.flight = (
            DropFlight(self.drop_watch, stages.flight.extend_speed, stages.flight.max_extension)
            if stages.flight is not None
            else None
        )
        landing = None  # the landing ridden flat-footed (``[stages.flight] landing``)
        if self.flight is not None and stages.flight is not None and stages.flight.landing:
            landing = LandingLoads(
                self.flight, self._contact_foot, stages.flight.landing, stages.flight.landing_depth
            )
        self.targets = TargetsFromPlan(  # the whole-body QP's targets from the plan in force
            self._read_plan, self.feet_targets, self.flight, self.shoes, self._sites_match, landing
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
            from_sent=self.pair.description.mpc.handover_from_sent,
        )
        # the ride starts on the backup until the MPC is ready (mpc/readiness.py)
        self.readiness = start_readiness(stages.takeover, RETURN_DWELL_S)
        if self.readiness is not None:
            self.handover.start_on_backup()
        self.watch = PlanWatch(self.handover, self.readiness, self.payload, self._standby_every)
        # where each solve runs and when its plan takes over (mpc/plan_solver.py)
        self.solver = PlanSolver(latency, self._build_and_run, self._build_in_process)
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
                weighed(
                    stages.payload, self.layout.names["vz"], self.payload, self.mpc.settings.dt
                ),
                start_weight(stages.payload),
            )
            if self.payload is not None
            else None
        )
        self._build_stages()

    def _build_and_run(self, inputs: BuildInputs) -> Built:
        """The MPC problem of one tick built from ``inputs``, shaped by the rider's
        problem shapers in order (:attr:`shapers`) and solved
        (:func:`~ridempc.mpc.stages.build.build_and_run`)."""
        return build_and_run(self.mpc, self.shapers, inputs)

    def _build_in_process(self, inputs: BuildInputs) -> Built:
        """:meth:`_build_and_run` in the solver process, its reply without the problem
        (a few hundred kB to send and read back) unless ``keeps_problems``."""
        built = self._build_and_run(inputs)
        return built if self.keeps_problems else built._replace(problem=None)

    @property
    def off_tick(self) -> str:
        """Where a late plan's solve runs (:data:`~ridempc.mpc.plan_solver.OFF_TICK`)."""
        return self.solver.off_tick

    @off_tick.setter
    def off_tick(self, where: str) -> None:
        self.solver.off_tick = where

    @property
    def _worker(self) -> SolverProcess[BuildInputs, Built] | None:
        """The solver process, if one was started (the bench reads its problems back)."""
        return self.solver.worker

    @property
    def _pending(self) -> PendingSolve | None:
        """The solve under way until its plan's take-up, if any."""
        return self.solver.pending

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
        self.triggers = handover_triggers(
            self.drop_watch,
            self.push_watch,
            self.flight,
            not self.hands_over_deviations,
            self.pair.description.mpc.handover_deviation,
        )

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
        lean, the shoes' lines and drags, the slope's speed trim, the swing's held forces)."""
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
            SlopeTrim(layout, self._shoe_columns) if self._slope_trim else None,
            HeldForces(mpc, step) if step is not None else None,
        )
