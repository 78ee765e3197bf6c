"""Handing the ride to a backup balance law and back, with the motor commands blended.

A tracking controller (the MPC rider) rides while its plans and whole-body QPs solve and
its state stays near its reference. When one of them fails, the ride is handed to a
*backup* law that balances the same robot on the same board from the same sensors (the
pair's PD baseline, :data:`ridempc.controllers.registry.CONTROLLERS`), and handed back
once the tracking controller has been *fit* again for :data:`RETURN_DWELL_S` (doubled at
each further handover, :meth:`Handover.dwell`), at most :data:`RETURNS` times a ride:

.. math:: u = (1 - \\alpha)\\, u_{from} + \\alpha\\, u_{to}, \\qquad
          \\alpha = \\min\\big(1, (t - t_{switch}) / T_{blend}\\big)

over every field of the motor command (feedforward torque, targets and gains). A backup
handed a rider in another posture than its own (the MPC twists the pelvis over the feet, or
crouches) would pull every joint to its posture at once, its stiffness times the posture's
error (0.25 rad of hip yaw at 300 N m/rad: 75 N m, which turns the shoes under the rider);
so, bumpless, the offset between the joints and the backup's position targets at the
handover is laid over those targets and fades out (:class:`PostureFade`), while every
change of the targets after it (the backup's feedback) passes at once:

.. math:: q^{des}(t) = q^{des}_{to}(t) + (1 - w(t))\\,(q(t_{switch}) - q^{des}_{to}(t_{switch})),
          \\qquad w(t) = \\tfrac12 \\big(1 - \\cos(\\pi \\min(1, (t - t_{switch}) / T_{fade}))\\big)

The backup
runs beside the primary (hot standby): its estimator, filters and integrators are current
at the moment it takes over, and its nominal posture is the one it took at the ride's
start, as when it rides alone.

The standby would cost the backup's whole tick at every tick. Most of that is its state
estimator, the same filter on the same sensors as the primary's where both see the same
platforms: there it reads the primary's estimate instead (:func:`share_estimator`), and
runs in standby only every :data:`STANDBY_DIVIDER` ticks while the primary holds the rider
settled. Sampled that sparsely, the backup's time-based logic credits a step of the state
to the whole interval since its last sample (a foot read unloaded once counts as unloaded
for 30 ms, and a leg reaches down after a shoe that never fell); a backup handed the ride
then commands its own state, not the rider's. So while the rider is off its reference
(beyond the return band, where a handover may follow) it runs every tick, as in its own
ride (:func:`standby_every`).

A handover in the rider's first divergence time of a ride that started on the primary
takes no posture fade (:meth:`Handover.fade_for`). A posture the primary *chose* (a deeper
crouch, a pelvis twisted over the feet) takes its plan longer than the rider's divergence
time to build,

.. math:: T_{start} = 1 / \\omega = \\sqrt{h / g}

(0.28 s for Cassie's centre of mass 0.8 m over her feet), since a plan brings a crouch in
over seconds and a lean grows no faster than :math:`e^{\\omega t}`. A handover before
:math:`T_{start}` finds no such posture, only the first ticks' tracking error of a model that
does not fit the rider yet (a payload, a moved centre of mass: a knee bent 0.14-0.18 rad off
the backup's targets within 0.064 s where the backup alone keeps it within 0.04 rad); laid
over the backup's targets it would be held for half a second, and the backup, which stands
the ride from its own start, would ride on from a buckled leg. So the backup's targets apply
at once, as in its own ride. Only the ride's first handover, and only where the primary
took the ride at the start (after a start on the backup the primary's posture at its
takeover is the backup's own).

A ride may also *start* on the backup (:meth:`Handover.start_on_backup`): the primary then
takes the ride, blended in as on a return, the first tick it is *ready*
(:mod:`ridempc.mpc.readiness` decides when); the start is not a fallback, and the time the
backup held it is :attr:`Handover.takeover_s`.

Nothing here names a robot, a board or a law: :class:`Handover` takes the backup as a
:class:`~ridempc.controllers.base.Controller` and is told, each tick, the primary's
command (or None), why it failed (or None) and whether it is fit to ride.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.controllers.base import Controller
from ridempc.estimation import EstimatedState, StateEstimator
from ridempc.gravity import GRAVITY
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = [
    "BLEND_S",
    "HANDOVER_DEVIATION",
    "LEAD_DEVIATION",
    "RETURN_DEVIATION",
    "RETURN_DWELL_S",
    "RETURNS",
    "STANDBY_DIVIDER",
    "Fallback",
    "POSTURE_FADE_S",
    "Handover",
    "PostureFade",
    "SharedEstimate",
    "blend",
    "deviation",
    "share_estimator",
    "standby_every",
    "start_window",
]

# [s] the blend of the two laws' commands: 10 ticks at 500 Hz, so no field of the command
# steps by more than a tenth of the two laws' difference in a tick, and a failed law's
# command is out within 20 ms (0.1 and 0.3 s changed nothing on the ride tried, Segway
# stand-still seed 6).
BLEND_S: float = 0.02
# [s] the fade of the posture's offset at a handover (PostureFade): a rider's divergence
# time and a half (Cassie's 1/omega = 0.3 s), so that the backup's posture comes back slower
# than the lean it balances grows, and its feedback, not the posture, sets the first steps
POSTURE_FADE_S: float = 0.5
# [s] how long the primary must be fit before it rides again, the hysteresis in time: 15
# MPC solves in a row near the reference, so that one good solve in a fall, or a rider at
# the edge of the primary's region, does not hand the ride back and forth.
RETURN_DWELL_S: float = 0.5
# [-] how many times a ride the primary takes the ride back after a handover: once, after
# a transient it could not ride (a push, a start's sway); a second handover shows an error
# that stays (the rider's or the board's parameters, constant within a ride) and that its
# model met again, so the backup, which needs no model, keeps the ride.
RETURNS: int = 1
# [-] the primary's state error, in units of what its weights accept (:func:`deviation`),
# beyond which the ride is handed over, unless the pair sets its own (``[mpc]
# handover_deviation``, the backup's basin where it is narrower): 1.7 times the largest the
# MPC reached in the library's manoeuvres (1.40-1.75: Segway push and velocity-steps,
# Hovershoes velocity-steps, skateboard push-off-0.5), the edge of its linear model.
HANDOVER_DEVIATION: float = 3.0
# [-] the same bound for the deviation's divergent lead while the primary is on probation
# (:mod:`~ridempc.mpc.divergence`): a forecast a divergence time ahead, which a start's
# transient the MPC rides reaches (2.97 on the Segway's velocity-steps, seed 0), and a
# handover by it finds the backup within its basin (the handed PD stood in 42 of 57 such
# rides); 1.7 times the library's largest deviation.
LEAD_DEVIATION: float = 3.0
# [-] the same error below which the primary may ride again: under half the handover's,
# the band between them the hysteresis (standing still on the Hovershoes it sits at
# 0.55-0.67 once settled).
RETURN_DEVIATION: float = 1.0
# [ticks] the backup's standby rate while the primary rides, where it reads the primary's
# estimate (SharedEstimate): every 15th tick (33 Hz at 500 Hz). Its filters, integrators and
# rate limits step by the sample times, so they stay current; the first tick (where it takes
# its nominal posture) and every tick from a handover on run it in full.
STANDBY_DIVIDER: int = 15
# [s] times within this are equal: a tick's time carries the rounding of its sum
TIME_TOLERANCE: float = 1e-9
# [m] the least centre-of-mass height start_window takes: a height not yet measured is no
# reason for a window of zero
MIN_COM_HEIGHT: float = 0.1


def start_window(com_height: float) -> float:
    """:math:`T_{start} = \\sqrt{h/g}` [s], the rider's divergence time, with the centre of
    mass ``com_height`` [m] over the feet (at least :data:`MIN_COM_HEIGHT`)."""
    return math.sqrt(max(com_height, MIN_COM_HEIGHT) / GRAVITY)


@dataclass
class Fallback:
    """One handover to the backup.

    Attributes:
        time_s: When it began [s].
        reason: Why the primary could not ride.
        duration_s: How long the backup rode [s]; None while it still rides.
    """

    time_s: float
    reason: str
    duration_s: float | None = None

    def record(self) -> dict[str, Any]:
        """For ``summary.json``."""
        return {"time_s": self.time_s, "reason": self.reason, "duration_s": self.duration_s}


class PostureFade:
    """The offset between the joints and a law's position targets at a switch, fading out
    over ``duration`` [s] from ``start`` [s] (the module's :math:`q^{des}(t)`).

    Args:
        start: The switch's time [s].
        offset: :math:`q(t_{switch}) - q^{des}_{to}(t_{switch})` per motor [rad].
        duration: :math:`T_{fade}` [s].
    """

    def __init__(self, start: float, offset: NDArray[np.float64], duration: float) -> None:
        self.start = start
        self.offset = offset
        self.duration = duration

    def done(self, now: float) -> bool:
        return now - self.start >= self.duration - TIME_TOLERANCE

    def __call__(self, now: float, command: MotorCommand) -> MotorCommand:
        """``command`` with what remains of the offset at ``now`` [s] on its targets."""
        if self.done(now):
            return command
        remaining = 0.5 * (1.0 + math.cos(math.pi * max(now - self.start, 0.0) / self.duration))
        return dataclasses.replace(command, position=command.position + remaining * self.offset)


def blend(start: MotorCommand, end: MotorCommand, alpha: float) -> MotorCommand:
    """:math:`(1 - \\alpha)\\, start + \\alpha\\, end`, field by field."""
    if alpha >= 1.0:
        return end
    a, b = 1.0 - alpha, alpha
    return MotorCommand(
        torque=a * start.torque + b * end.torque,
        position=a * start.position + b * end.position,
        velocity=a * start.velocity + b * end.velocity,
        kp=a * start.kp + b * end.kp,
        kd=a * start.kd + b * end.kd,
    )


class Handover:
    """Which law rides, and the blend between them.

    Args:
        backup: The backup law.
        blend_s: :math:`T_{blend}` [s].
        dwell_s: How long the primary must be fit before it rides again [s].
        returns: How many times a ride the primary rides again after a handover.
        standby_every: While the primary rides, the backup runs at every this many ticks
            (1: every tick, as it must with an estimator of its own); half a period after
            the first, off the ticks a primary with a slower loop of its own starts from.
        standby_phase: The tick of each ``standby_every`` the standby runs on (None: half
            a period, ``standby_every // 2``; :func:`~ridempc.mpc.stagger.standby_phase`).
        fade_s: :math:`T_{fade}` [s] (0: none); none in a start's first divergence time
            (:meth:`fade_for`).
        from_sent: Blend a handover out of the command sent the tick before, not out of the
            failing tick's own (which the triggers judged unfit: on the Segway a plan solved
            past the model's edge asks the knees for 100-225 N m off the tick before's, a kick
            that slides both feet on the one deck they share, where the handed PD, with no
            sensor of where its feet stand on the deck, cannot put them back).

    Attributes:
        fallbacks: Every handover so far, in order.
    """

    def __init__(
        self,
        backup: Controller,
        blend_s: float = BLEND_S,
        dwell_s: float = RETURN_DWELL_S,
        standby_every: int = 1,
        standby_phase: int | None = None,
        fade_s: float = POSTURE_FADE_S,
        returns: int = RETURNS,
        from_sent: bool = False,
    ) -> None:
        self.backup = backup
        self.from_sent = from_sent
        self._sent: MotorCommand | None = None  # what step returned last: the motors' command
        self.returns = returns
        self.fade_s = fade_s
        self._fade: PostureFade | None = None  # the posture's offset at the last handover
        self.standby_every = standby_every
        self.standby_phase = standby_every // 2 if standby_phase is None else standby_phase
        self._ticks = 0
        self._backup_command: MotorCommand | None = None
        self.blend_s = blend_s
        self._blend_now = blend_s  # [s] the blend of the last switch
        self.dwell_s = dwell_s
        self.fallbacks: list[Fallback] = []
        self._switch_time: float | None = None  # [s] the last switch, either way
        self._from: MotorCommand | None = None  # the command blended out of since then
        self._fit_since: float | None = None
        self._last_primary: MotorCommand | None = None
        self.starting = False  # the backup holds the ride's start (start_on_backup)
        self.takeover_s: float | None = None  # [s] when the primary took the start's ride
        self._start: float | None = None  # [s] the ride's first tick

    def start_on_backup(self) -> None:
        """The ride starts on the backup; the primary takes it when ``step`` is told it is
        ready, at once (no dwell: its readiness has its own)."""
        self.starting = True

    def dwell(self) -> float:
        """How long the primary must be fit before it rides again [s]: :attr:`dwell_s`,
        doubled at each handover after the first, so that a primary that keeps failing
        (a model error it cannot absorb) rides less and less; infinite once it has taken
        the ride back :attr:`returns` times (it stays on the backup)."""
        if len(self.fallbacks) > self.returns:
            return math.inf
        return self.dwell_s * 2.0 ** max(len(self.fallbacks) - 1, 0)

    def fade_for(self, now: float, com_height: float | None) -> float:
        """The posture fade [s] for a handover at ``now`` [s]: none for the ride's first
        handover within :func:`start_window` of its start, where the primary took the ride
        at the start, with the centre of mass ``com_height`` [m] over the feet (None: not
        known, the configured fade); :attr:`fade_s` otherwise."""
        if com_height is None or self._start is None:
            return self.fade_s
        on_primary_from_start = self.takeover_s is None and not self.starting
        early = now - self._start < start_window(com_height)
        return 0.0 if on_primary_from_start and early and not self.fallbacks else self.fade_s

    @property
    def on_backup(self) -> bool:
        """Whether the backup rides."""
        return self.starting or bool(self.fallbacks) and self.fallbacks[-1].duration_s is None

    def step(
        self,
        sensors: SensorPacket,
        command: Command,
        primary: MotorCommand | None,
        failure: str | None,
        fit: bool,
        com_height: float | None = None,
        blend_s: float | None = None,
    ) -> MotorCommand:
        """One tick: the backup updated, the handover decided, the command to send, kept
        for the next handover's blend (``from_sent``).

        Args:
            sensors: This tick's packet (for the backup).
            command: The ride's command (for the backup).
            primary: The primary's command this tick, None where it has none.
            failure: Why the primary cannot ride this tick, None if it can.
            fit: Whether the primary is fit to ride again (plans and QPs solving, the state
                near its reference); read only while the backup rides. While it holds the
                start: whether the primary is ready to take it.
            com_height: The centre of mass over the feet [m], for the start's window
                (:meth:`fade_for`); None: not known.
            blend_s: The blend [s] of a handover this tick (None: :attr:`blend_s`; a
                push's, :func:`~ridempc.mpc.push_handover.push_blend`).
        """
        self._sent = self._step(sensors, command, primary, failure, fit, com_height, blend_s)
        return self._sent

    def _step(
        self,
        sensors: SensorPacket,
        command: Command,
        primary: MotorCommand | None,
        failure: str | None,
        fit: bool,
        com_height: float | None,
        blend_s: float | None,
    ) -> MotorCommand:
        """:meth:`step`'s decision, every return path of it."""
        now = sensors.time
        self._start = now if self._start is None else self._start
        backup = self._backup(sensors, command, primary is None or failure is not None)
        if self.starting:
            if failure is None and primary is not None and fit:
                self.starting, self.takeover_s = False, now
                self._switch(now, self._blended(now, backup))
                self._last_primary = primary
                return self._blended(now, primary)
            return self._blended(now, backup)
        if not self.on_backup:
            if failure is None and primary is not None:
                self._last_primary = primary
                return self._blended(now, primary)
            start = primary if primary is not None else self._last_primary
            if self.from_sent and self._sent is not None:
                start = self._sent  # what the motors hold, never the unfit tick's command
            fade_s = self.fade_for(now, com_height)
            self.fallbacks.append(Fallback(now, failure or "no command"))
            self._switch(now, start if start is not None else backup, blend_s)
            self._fit_since = None
            if fade_s > 0.0:
                joints = np.asarray(sensors.joint_position[: len(backup.position)], dtype=float)
                self._fade = PostureFade(now, joints - backup.position, fade_s)
            return self._blended(now, self._faded(now, backup))
        if failure is None and primary is not None and fit:
            self._fit_since = now if self._fit_since is None else self._fit_since
            if now - self._fit_since >= self.dwell() - TIME_TOLERANCE:
                current = self.fallbacks[-1]
                current.duration_s = now - current.time_s
                self._switch(now, self._blended(now, self._faded(now, backup)))
                self._fade = None
                self._last_primary = primary
                return self._blended(now, primary)
        else:
            self._fit_since = None
        return self._blended(now, self._faded(now, backup))

    def _backup(self, sensors: SensorPacket, command: Command, needed: bool) -> MotorCommand:
        """The backup's command: run this tick where it rides, is blended or ``needed`` and
        on its first tick; every :attr:`standby_every` ticks in standby only its state
        advanced (:meth:`~ridempc.controllers.base.Controller.standby`), the command it
        last gave kept, which nothing reads before its next update."""
        tick, self._ticks = self._ticks, self._ticks + 1
        every = self.standby_every
        standby = tick % every == self.standby_phase if every > 1 else True
        if (
            self._backup_command is None
            or needed
            or self.on_backup
            or self._switch_time is not None
        ):
            self._backup_command = self.backup.update(sensors, command)
        elif standby:  # its command not read before the next update: its state only
            # (a stand-in law without the Controller's hook: updated in full)
            getattr(self.backup, "standby", self.backup.update)(sensors, command)
        return self._backup_command

    def _faded(self, now: float, command: MotorCommand) -> MotorCommand:
        """The backup's ``command`` with the posture's offset at the handover, fading."""
        if self._fade is None:
            return command
        if self._fade.done(now):
            self._fade = None
            return command
        return self._fade(now, command)

    def _switch(self, now: float, start: MotorCommand, blend_s: float | None = None) -> None:
        self._switch_time, self._from = now, start
        self._blend_now = self.blend_s if blend_s is None else blend_s

    def _blended(self, now: float, target: MotorCommand) -> MotorCommand:
        """``target``, blended in from the last switch's command over that switch's blend."""
        if self._switch_time is None or self._from is None:
            return target
        elapsed = now - self._switch_time + TIME_TOLERANCE
        alpha = elapsed / self._blend_now if self._blend_now > 0.0 else 1.0
        if alpha >= 1.0:
            self._switch_time = self._from = None
            return target
        return blend(self._from, target, max(alpha, 0.0))

    def summary(self) -> list[dict[str, Any]]:
        """Every handover, for ``summary.json``'s ``fallbacks``."""
        return [f.record() for f in self.fallbacks]


def standby_every(divider: int, warming: bool, settled: bool) -> int:
    """How often the backup runs in standby [ticks]: every tick while it is ``warming`` (its
    filters settling from rest) or the primary's rider is not ``settled`` (its deviation
    beyond :data:`RETURN_DEVIATION`: a handover may come, and the backup must take it with
    the state it would have in its own ride), else every ``divider`` ticks."""
    return 1 if warming or not settled else divider


def deviation(
    state: NDArray[np.float64], reference: NDArray[np.float64], weights: NDArray[np.float64]
) -> float:
    """How far ``state`` is from ``reference``, in units of what the weights accept: with
    each state's weight the inverse square of its acceptable error,
    :math:`Q_i = 1/\\sigma_i^2` (Bryson's rule, as the MPC's weights are set),

    .. math:: d = \\sqrt{\\tfrac1n \\textstyle\\sum_i Q_i (x_i - x^{ref}_i)^2}

    [-], the root mean square over the :math:`n` states: :math:`d \\le 1` is the states
    within their acceptable errors on the whole.
    """
    squared = np.maximum(weights, 0.0) * (state - reference) ** 2
    return float(np.sqrt(np.mean(squared))) if squared.size else 0.0


class SharedEstimate:
    """A backup's stand-in for its state estimator: the primary's estimator, updated by the
    primary each tick before the backup runs, which ``reset`` and ``update`` only read;
    where the primary's estimate is not finite (a diverged filter, a sensor fault), the
    backup's own estimator restarts from that packet and runs on alone from then on.

    Args:
        estimator: The primary's estimator.
        own: The backup's own estimator (the same filter), idle while shared.
    """

    def __init__(self, estimator: StateEstimator, own: StateEstimator) -> None:
        self._estimator = estimator
        self._own = own
        self.detached = False

    @property
    def state(self) -> EstimatedState | None:
        return (self._own if self.detached else self._estimator).state

    def reset(self, packet: SensorPacket, *args: Any, **kwargs: Any) -> EstimatedState | None:
        return self.update(packet)

    def update(self, packet: SensorPacket) -> EstimatedState | None:
        if self.detached:
            return self._own.update(packet)
        state = self._estimator.state
        if state is not None and np.isfinite(state.q).all() and np.isfinite(state.v).all():
            return state
        self.detached = True
        return self._own.reset(packet)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._own if self.detached else self._estimator, name)


def share_estimator(backup: Controller, estimator: StateEstimator) -> bool:
    """Give ``backup`` the primary's ``estimator`` in place of its own
    (:class:`SharedEstimate`), where its own is the same filter (the same robot,
    platforms and support height); returns whether it did."""
    own = getattr(backup, "estimator", None)
    if not isinstance(own, StateEstimator):
        return False
    same = (
        own.robot is estimator.robot
        and own.platforms == estimator.platforms
        and own.support_height == estimator.support_height
    )
    if same:
        backup.estimator = SharedEstimate(estimator, own)  # type: ignore[attr-defined]
    return same
