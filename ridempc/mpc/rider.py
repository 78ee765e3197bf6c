"""``mpc``: the skateboard paper's pipeline (section V) riding any pair with an MPC library.

The rider is a short loop over stages, each of one protocol
(:mod:`ridempc.mpc.stages.base`), built once from the pair file's ``[stages.*]``
(``pairs/<robot>-<board>.toml``) by :class:`~ridempc.mpc.rider_parts.RiderParts` and listed
there, in the order they act. Every 2 ms (500 Hz) the rider

1. estimates its state from the sensors (:class:`~ridempc.estimation.StateEstimator`, the
   board from its own feet), each shoe's heading from its direction of travel, and
   updates the **tick observers** (``observers``: the platforms falling away,
   :class:`~ridempc.mpc.stages.triggers.DropWatch`, the drop's flight,
   :class:`~ridempc.mpc.flight.DropFlight`, the stance's loads for the payload,
   :mod:`~ridempc.mpc.stages.payload_models`);
2. every :data:`MPC_DIVIDER`-th tick (30 Hz), asks the **command sources**: the manoeuvre
   the command asks for (:class:`~ridempc.mpc.stages.manoeuvre_choice.ManoeuvreChoice`), the
   commanded roll and turn over the horizon and the state in the library frame moved onto
   the board (:class:`~ridempc.mpc.stages.frame_follow.CommandedFrame`, reading
   :class:`~ridempc.mpc.stages.commands.CommandHorizon`); sums the **drift sources**
   (``drifts``, disturbance observers: the deck's torque, the payload, the steady
   disturbance, the lean's pull) into the MPC's rates; and has the problem built, shaped
   by the **problem shapers** in order (``shapers``: coasting, the commanded roll, a
   re-push's blend, the turn, the Segway's crouch and lean, the Hovershoes' lines and
   drags, the swing's held forces) and solved (:func:`~ridempc.mpc.stages.build.build_and_run`)
   in the tick, the solver thread or the solver process
   (:class:`~ridempc.mpc.plan_solver.PlanSolver`), from the state predicted at the plan's
   take-up ``plan_latency`` ticks later (:mod:`ridempc.mpc.delay`);
3. takes a plan up at its tick (:class:`~ridempc.mpc.plan_book.PlanBook`, watched by the
   handover's :class:`~ridempc.mpc.stages.plan_watch.PlanWatch`), reads it into
   whole-body targets (:class:`~ridempc.mpc.stages.wbc_targets.TargetsFromPlan`: the plan
   at its age, the feet's support and swing, each shoe's drag as its platform's
   acceleration) and solves the whole-body QP (:class:`~ridempc.wbc.WholeBodyController`);
4. updates the observers of the QP's output (``wbc_observers``: the shoes' observer, the
   push's watch), asks the **handover triggers** in order (``triggers``,
   :mod:`~ridempc.mpc.stages.triggers`) why the MPC cannot ride, and sends the QP's torques
   as feedforward, each led over its motor's torque delay (:mod:`~ridempc.wbc.torque_lead`),
   with its joint targets to the motor PD.

**Fallback.** The whole-body QP always returns a command (slack on its soft rows,
:mod:`ridempc.wbc.elastic`). If the MPC's QP fails (its previous plan shifted by one step is
then used), anything raises, the estimate is not finite, or a trigger gives a reason, the
ride is handed to the pair's PD baseline (:data:`BACKUP_LAW`, in standby beside the MPC),
the motor commands blended, and handed back once the MPC's plans have solved and its state
has stayed near the reference for a while (:mod:`~ridempc.mpc.handover`); each handover is
in ``summary()``'s ``fallbacks``. With the pair's ``takeover`` stage the ride starts on that
backup until the MPC is ready (:mod:`~ridempc.mpc.readiness`). Only where the backup too
has no finite command are the joints held where they are (``safe_hold``). What the ride
reports (``summary()``, ``diagnostics()``) is in :mod:`~ridempc.mpc.rider_reports`.
"""

from __future__ import annotations

import copy
import math
import time

import numpy as np
from numpy.typing import NDArray

from ridempc.errors import RidempcError
from ridempc.estimation import EstimatedState
from ridempc.mpc.handover import RETURN_DEVIATION
from ridempc.mpc.manoeuvre import HOLD, REPUSH, REPUSH_BAND
from ridempc.mpc.plan_solver import PROCESS_MIN_LATENCY
from ridempc.mpc.platform_feet import platform_feet, rolling_platforms
from ridempc.mpc.push_handover import deviation_deferred, push_blend
from ridempc.mpc.rider_parts import BACKUP_LAW, MPC_DIVIDER
from ridempc.mpc.rider_reports import RiderReports
from ridempc.mpc.stages.base import ControlTick, MpcTick
from ridempc.mpc.stages.build import BuildInputs, Built, PendingSolve
from ridempc.mpc.stages.plan_watch import STANDBY_WARMUP_S
from ridempc.mpc.stages.support import foot_support
from ridempc.mpc.stages.triggers import HandoverCheck
from ridempc.mpc.state_map import forward_speed
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket
from ridempc.trajopt.schedule import Contact
from ridempc.wbc import to_motor_command
from ridempc.wbc.qp import WbcFailed
from ridempc.wbc.targets import WbcOutput

__all__ = [
    "BACKUP_LAW",
    "MPC_DIVIDER",
    "PROCESS_MIN_LATENCY",
    "STANDBY_WARMUP_S",
    "MpcRider",
    "platform_feet",
    "rolling_platforms",
]

Array = NDArray[np.float64]


class MpcRider(RiderReports):
    """MPC at 30 Hz over the robot and its board, whole-body QP at 500 Hz.

    Args:
        robot: The rider.
        board: The board's name; the pair needs an MPC library.
        settings: MPC settings.
        wbc_solver: The whole-body QP's solver (:data:`~ridempc.wbc.settings.SOLVERS`);
            None: the registry's (:data:`~ridempc.solvers.QP_KINDS`).
        plan_latency: Ticks from the state a solve starts from to its plan's take-up,
            0 to ``MPC_DIVIDER - 1`` (:mod:`~ridempc.mpc.plan_solver`); None: the pair's.
        backup: The law the ride is handed to when the MPC fails
            (:mod:`~ridempc.mpc.handover`); None: the registry's :data:`BACKUP_LAW` for
            the pair.
        hands_over_deviations: Whether a push or a deviation from the reference hands the
            ride to the backup law; False: only the MPC's own failures (a failed plan, a
            drop, a whole-body QP on slack), the ``mpc-alone`` ablation.

    Raises:
        UnknownNameError: No MPC for this robot-board pair.
        ConfigError: Its library is missing or corrupt, or an unknown ``wbc_solver``.
        ValueError: ``plan_latency`` outside 0 to ``MPC_DIVIDER - 1``.
    """

    rate_hz = 500.0

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
        self.book.plan = None
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
        pushed = self.push_watch is not None and self.push_watch.handed(failure)
        blend_s = push_blend(self._com_height, self.handover.blend_s) if pushed else None
        height = self._com_height
        out = self.handover.step(sensors, command, primary, failure, self._fit(), height, blend_s)
        if starting and not self.handover.starting:  # its rate measured the backup's ride
            self.watch.divergence.reset()  # away from plans it did not follow
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
            solve = self.solver.due(self._tick)
            if solve is not None:
                self._adopt_pending(solve)
            if self.book.plan is None:
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
            self.book.plan,
            self._diagnostics.get("wbc_slack", 0.0),
            self.book.deviation,
            stroke,
            self.watch.probation.proven,
            self.watch.divergence,
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
        plan = self.book.plan
        if self.handover.starting:  # the start's backup: until the MPC is ready
            return self.readiness is not None and self.readiness.ready
        settled = max(self.book.deviation, self.watch.divergence.value) <= RETURN_DEVIATION
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
            self.watch.divergence.reset()  # a new reference: its deviation steps, no divergence
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
        held = self.handover.on_backup or self.solver.pending is not None  # the plan not followed
        tick = MpcTick(
            estimate,
            now,
            speed,
            balancing,
            self.book.plan,
            self.book.time,
            0.0,
            held,
            self._diagnostics,
        )
        if self.payload_models is not None:
            self.payload_models.absorb(tick)
        pushing = Contact.GROUND in self.book.contacts  # a foot on the ground goes straight
        steering = balancing or (self.manoeuvre.kind == REPUSH and not pushing)
        if self.shoes is not None and self._slope_trim:  # a slope's lost speed: mpc/slope_trim.py
            riding, slopes = not self.handover.on_backup, self.shoes.slopes.angles
            self.shoes.trim.update(now, command.velocity, rider_speed, slopes, riding)
        roll, turn, x0 = self.commanded(tick, command, mapped, t_ref, coasting, steering)
        started = time.perf_counter()
        turned = math.remainder(self.map.frame.yaw - self.book.frame.yaw, 2.0 * math.pi)
        tick = tick._replace(frame_turn=turned)  # the frame has moved onto the board
        drift: Array | None = None
        for source in self.drifts:  # the disturbance observers' drifts, summed in order
            more = source.drift(tick, x0)
            if more is not None:
                drift = more if drift is None else drift + more
        # the plan starts where it takes over (mpc/delay.py): the first plan is waited for
        late = self.plan_latency > 0 and self.book.plan is not None and self.predicts_start
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
            (self.manoeuvre.kind, self.manoeuvre.target, self.manoeuvre.gain),
            self.book.plan.first_input if self.book.plan is not None else None,
            self.book.contacts,
            None if self.mpc.reference is self._sent_reference else self.mpc.reference,
            began,
            command.lateral_offset,
            delay,
        )
        self._sent_reference = self.mpc.reference
        # the frame the plan is in: the map's moves on at the next tick, the plan only
        # when this one takes over
        pending = PendingSolve(self.map.frame, now + delay, self._tick + self.plan_latency)
        built = self.solver.start(pending, inputs, first=self.book.plan is None)
        if built is not None:
            self._adopt(pending, built)
        self._mpc_main_s += time.perf_counter() - started

    def close(self) -> None:
        """End the MPC's solver process, if one was started (at the end of a ride)."""
        self.solver.close()

    def _adopt_pending(self, solve: PendingSolve) -> None:
        """The pending ``solve``'s plan taken up, its tick come (waiting for it if the
        solver is still at it)."""
        assert solve.reply is not None
        started = time.perf_counter()
        self._adopt(solve, solve.reply.result())
        self._mpc_main_s += time.perf_counter() - started

    def _adopt(self, solve: PendingSolve, built: Built) -> None:
        """The plan of ``solve`` (its problem ``built`` and solved) in force from this tick
        on, timed from the state it was solved from, and watched by the handover."""
        self.book.record(built)
        self._diagnostics["mpc_deviation"] = built.deviation
        # a stop is the selector's ride-out of a push, which the backup rides too
        commanded = self.manoeuvre.kind not in (HOLD, "stop")
        self.watch.observe(solve.time, built, self._com_height, commanded)
        plan = self.book.adopt(solve, built)
        self._set_support(built.contacts)
        self._diagnostics.update(
            mpc_ms=self.book.ms[-1],
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
        """The board's forward speed [m/s] (on flat ground, the base's horizontal speed)."""
        if estimate.boards:
            return forward_speed(estimate.boards[0])
        return float(np.linalg.norm(estimate.base_velocity[:2]))

    def _wbc_tick(self, estimate: EstimatedState, now: float) -> tuple[MotorCommand, WbcOutput]:
        """The whole-body QP's motor command for the plan in force at ``now`` [s], and its
        output."""
        assert self._support is not None  # set by the MPC tick, which runs first
        t_ref = self.manoeuvre.reference_time(now)
        targets = self.targets(self.book, self._support, t_ref, estimate, now)
        out = self.wbc.solve(estimate, targets)
        self._wbc_ms.append(out.model_ms + out.build_ms + out.solve_ms)
        slack = self.wbc.last_solution.slack if self.wbc.last_solution is not None else 0.0
        self._wbc_slack_max = max(self._wbc_slack_max, slack)
        self._diagnostics.update(wbc_ms=self._wbc_ms[-1], wbc_slack=slack)
        torque = self.torque_lead(now, out.torque)
        return to_motor_command(out, self.kp, self.kd, torque=torque), out
