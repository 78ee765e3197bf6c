"""The handover between the MPC and a backup law (``ridempc.mpc.handover``), without a ride:
a stand-in backup and made-up commands, ticked at 500 Hz."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.handover import (
    BLEND_S,
    POSTURE_FADE_S,
    Handover,
    blend,
    deviation,
    standby_every,
    start_window,
)
from ridempc.mpc.plan import Plan
from ridempc.mpc.stages.triggers import Deviated, HandoverCheck
from ridempc.pair_description import load_pair_description
from ridempc.sim.motors import MotorCommand

DT = 0.002  # [s] the rider's tick


def _command(value: float) -> MotorCommand:
    return MotorCommand(*(np.full(3, value) for _ in range(5)))


class _Backup:
    """A backup law that sends 1 everywhere and counts its ticks."""

    def __init__(self) -> None:
        self.ticks = 0

    def update(self, sensors: Any, command: Any) -> MotorCommand:
        self.ticks += 1
        return _command(1.0)


def _run(handover: Handover, ticks: int, start: int, fails: range, fit: bool = True) -> list:
    sent = []
    for k in range(start, start + ticks):
        sensors = SimpleNamespace(time=k * DT, joint_position=np.ones(3))
        failure = "WbcFailed: test" if k in fails else None
        sent.append(handover.step(sensors, None, _command(0.0), failure, fit))  # type: ignore[arg-type]
    return sent


def test_hands_over_at_the_first_failure_blended_and_back_after_the_dwell() -> None:
    backup = _Backup()
    handover = Handover(backup, dwell_s=0.1)  # type: ignore[arg-type]
    sent = _run(handover, 300, 0, range(50, 60))
    assert backup.ticks == 300  # hot standby: every tick
    torque = np.array([c.torque[0] for c in sent])
    assert np.all(torque[:50] == 0.0)  # the primary rides
    ramp = round(BLEND_S / DT)
    np.testing.assert_allclose(torque[50 : 50 + ramp], np.arange(ramp) / ramp, atol=1e-6)
    back = 60 + round(0.1 / DT)  # the first fit tick, then the dwell
    assert np.all(torque[50 + ramp : back] == 1.0)  # the backup rides
    np.testing.assert_allclose(torque[back : back + ramp], 1.0 - np.arange(ramp) / ramp, atol=1e-6)
    assert np.all(torque[back + ramp :] == 0.0)
    (record,) = handover.summary()
    assert record == {
        "time_s": pytest.approx(0.1),
        "reason": "WbcFailed: test",
        "duration_s": pytest.approx((back - 50) * DT),
    }


def test_stays_on_the_backup_while_the_primary_is_unfit() -> None:
    handover = Handover(_Backup(), dwell_s=0.1)  # type: ignore[arg-type]
    _run(handover, 200, 0, range(10, 11), fit=False)
    assert handover.on_backup and handover.summary()[0]["duration_s"] is None


def test_a_failure_in_the_dwell_starts_it_again() -> None:
    handover = Handover(_Backup(), dwell_s=0.1)  # type: ignore[arg-type]
    fails = set(range(10, 11)) | {50}  # fit from tick 11, failed again at 50
    sent = _run(handover, 200, 0, fails)  # type: ignore[arg-type]
    back = 51 + round(0.1 / DT)
    assert sent[back - 1].torque[0] == 1.0 and sent[back + 1].torque[0] < 1.0  # blended back
    assert handover.summary()[0]["duration_s"] == pytest.approx((back - 10) * DT)


def test_blend_and_deviation() -> None:
    mixed = blend(_command(0.0), _command(2.0), 0.25)
    assert mixed.kp[0] == pytest.approx(0.5) and mixed.torque[0] == pytest.approx(0.5)
    weights = np.array([400.0, 100.0, 0.0])  # sigmas 0.05, 0.1 and a free state
    assert deviation(np.array([0.05, 0.0, 9.0]), np.zeros(3), weights) == pytest.approx(
        np.sqrt(1 / 3)
    )


def test_the_dwell_doubles_at_each_further_handover() -> None:
    handover = Handover(_Backup(), dwell_s=0.1, returns=2)  # type: ignore[arg-type]
    _run(handover, 100, 0, range(10, 11))  # back at tick 61
    assert handover.dwell() == pytest.approx(0.1) and not handover.on_backup
    _run(handover, 200, 100, range(110, 111))
    assert len(handover.summary()) == 2 and handover.dwell() == pytest.approx(0.2)
    assert handover.summary()[1]["duration_s"] == pytest.approx(0.202)  # one tick, the dwell


def test_after_its_returns_the_backup_keeps_the_ride() -> None:
    """A primary handed over again after its one return (an error that stays within the
    ride) is not given the ride back, however long it is fit."""
    handover = Handover(_Backup(), dwell_s=0.1, returns=1)  # type: ignore[arg-type]
    _run(handover, 100, 0, range(10, 11))  # back at tick 61: the one return
    assert not handover.on_backup
    sent = _run(handover, 1000, 100, range(110, 111))  # fit for 1.8 s after the second
    assert handover.on_backup and handover.dwell() == float("inf")
    assert all(c.torque[0] == 1.0 for c in sent[-100:])  # the backup's command only
    assert handover.summary()[1]["duration_s"] is None


def test_in_standby_the_backup_runs_on_its_first_tick_then_every_nth() -> None:
    backup = _Backup()
    handover = Handover(backup, standby_every=15)  # type: ignore[arg-type]
    _run(handover, 45, 0, range(0))
    assert backup.ticks == 1 + 3  # tick 0, then 7, 22 and 37
    _run(handover, 20, 45, range(50, 51))  # from the failure on, every tick
    assert backup.ticks == 4 + 15  # none in standby at 45-49, then every tick of 50-64


class _Timer:
    """A backup with time-based logic, as a law's own: how long a flag (a foot unloaded) has
    been on, stepped by the sample times, as :class:`CassieHovershoes` counts a foot's."""

    def __init__(self) -> None:
        self.on_for = 0.0
        self.flag = False
        self._time: float | None = None

    def update(self, sensors: Any, command: Any) -> MotorCommand:
        step = 0.0 if self._time is None else sensors.time - self._time
        self._time = sensors.time
        self.on_for = self.on_for + step if self.flag else 0.0
        return _command(1.0)


def _timer_at_handover(settled_every: int, unsettled_from: int) -> float:
    """The time the flag is counted on when the ride is handed over, the flag on from tick
    100 and the handover at tick 110, the rider unsettled from ``unsettled_from``."""
    backup = _Timer()
    handover = Handover(backup, standby_every=settled_every)  # type: ignore[arg-type]
    for k in range(111):
        backup.flag = k >= 100
        handover.standby_every = standby_every(settled_every, False, settled=k < unsettled_from)
        failure = "test" if k == 110 else None
        sensors = SimpleNamespace(time=k * DT, joint_position=np.ones(3))
        handover.step(sensors, None, _command(0.0), failure, True)  # type: ignore[arg-type]
    return backup.on_for


def test_the_standby_runs_every_tick_while_the_rider_is_unsettled() -> None:
    assert standby_every(15, warming=False, settled=True) == 15
    assert standby_every(15, warming=True, settled=True) == 1
    assert standby_every(15, warming=False, settled=False) == 1
    # sampled every tick from the rider's unsettling on, the backup takes the ride with the
    # flag counted as in its own ride (each of ticks 100-110 its step); every 15th tick
    # alone, the sample before the flag's (tick 97) counts it on since then
    assert _timer_at_handover(15, unsettled_from=90) == pytest.approx(11 * DT)
    assert _timer_at_handover(15, unsettled_from=200) == pytest.approx(13 * DT)


class _Posture:
    """A backup holding its posture target, 1 rad, plus a step of 0.1 rad from tick 300."""

    def update(self, sensors: Any, command: Any) -> MotorCommand:
        target = 1.0 + (0.1 if sensors.time >= 300 * DT - 1e-9 else 0.0)
        return MotorCommand(np.zeros(3), np.full(3, target), np.zeros(3), np.ones(3), np.ones(3))


def test_a_handover_fades_the_posture_offset_and_passes_the_feedback_at_once() -> None:
    handover = Handover(_Posture(), blend_s=0.0)  # type: ignore[arg-type]
    targets = []
    for k in range(100, 700):
        joints = np.full(3, 0.6)  # the primary's posture: 0.4 rad off the backup's
        sensors = SimpleNamespace(time=k * DT, joint_position=joints)
        failure = "test" if k == 100 else None
        sent = handover.step(sensors, None, _command(0.0), failure, False)  # type: ignore[arg-type]
        targets.append(sent.position[0])
    half = round(POSTURE_FADE_S / DT / 2)
    assert targets[0] == pytest.approx(0.6)  # no step of the target at the handover
    assert targets[half] == pytest.approx(0.8)  # half the offset gone half-way
    # the backup's step at tick 300 passes whole, on top of what remains of the offset
    assert targets[200] - targets[199] == pytest.approx(0.1, abs=2e-3)
    assert targets[-1] == pytest.approx(1.1)  # then the backup's own target


class _Estimator:
    """A stand-in estimator: its state, and how often it was reset and updated."""

    def __init__(self, q: float) -> None:
        self.state = SimpleNamespace(q=np.array([q]), v=np.zeros(1))
        self.resets = self.updates = 0

    def reset(self, packet: Any) -> Any:
        self.resets += 1
        return self.state

    def update(self, packet: Any) -> Any:
        self.updates += 1
        return self.state


def test_a_shared_estimate_is_read_and_left_for_the_own_filter_when_not_finite() -> None:
    from ridempc.mpc.handover import SharedEstimate

    primary, own = _Estimator(1.0), _Estimator(2.0)
    shared = SharedEstimate(primary, own)  # type: ignore[arg-type]
    assert shared.reset(None).q[0] == 1.0 and shared.update(None).q[0] == 1.0  # type: ignore[arg-type, union-attr]
    assert primary.updates == primary.resets == own.updates == own.resets == 0
    primary.state.q[0] = np.nan
    assert shared.update(None).q[0] == 2.0 and own.resets == 1  # type: ignore[arg-type, union-attr]
    primary.state.q[0] = 1.0  # once left, the own filter runs on
    assert shared.update(None).q[0] == 2.0 and own.updates == 1  # type: ignore[arg-type, union-attr]
    assert shared.detached and shared.state.q[0] == 2.0  # type: ignore[union-attr]


def _joints_at(time: float) -> SimpleNamespace:
    return SimpleNamespace(time=time, joint_position=np.full(3, 0.5))


def test_the_start_window_is_the_riders_divergence_time() -> None:
    # Cassie's centre of mass 0.8 m over her feet: 1/omega = sqrt(0.8/9.81) = 0.286 s
    assert start_window(0.8) == pytest.approx(0.2856, abs=1e-4)
    assert start_window(1.2) > start_window(0.8)  # a taller rider diverges slower
    assert start_window(0.0) == pytest.approx(math.sqrt(0.1 / 9.81))  # never an empty window


def _handover_at(time: float, com_height: float | None) -> Handover:
    """A handover ridden on the primary from 0 s, failing at ``time`` [s]."""
    handover = Handover(_Backup(), blend_s=0.0)  # type: ignore[arg-type]
    for k in range(round(time / DT) + 1):
        failure = "deviation" if k * DT >= time - 1e-9 else None
        handover.step(_joints_at(k * DT), None, _command(0.0), failure, True, com_height)  # type: ignore[arg-type]
    return handover


def test_a_first_handover_in_the_starts_divergence_time_takes_no_fade() -> None:
    # the joints 0.5 rad off the backup's targets (1): no offset laid over them
    early = _handover_at(0.064, 0.8)  # the Segway's start handovers
    assert early.fade_for(0.064, 0.8) == POSTURE_FADE_S  # a second handover would fade
    sent = early.step(_joints_at(0.066), None, _command(0.0), "deviation", True, 0.8)  # type: ignore[arg-type]
    assert sent.position[0] == 1.0
    late = _handover_at(0.3, 0.8)  # past 0.286 s: a posture the plan chose, faded
    sent = late.step(_joints_at(0.302), None, _command(0.0), "deviation", True, 0.8)  # type: ignore[arg-type]
    assert sent.position[0] < 1.0


def test_the_start_window_needs_a_height_and_a_start_on_the_primary() -> None:
    unknown = _handover_at(0.064, None)  # no height told: the configured fade
    sent = unknown.step(_joints_at(0.066), None, _command(0.0), "deviation", True)  # type: ignore[arg-type]
    assert sent.position[0] < 1.0
    handover = Handover(_Backup())  # type: ignore[arg-type]
    handover.start_on_backup()
    handover.step(_joints_at(0.0), None, _command(0.0), None, False, 0.8)  # type: ignore[arg-type]
    assert handover.fade_for(0.1, 0.8) == POSTURE_FADE_S  # its posture at takeover: the backup's
    handover.starting, handover.takeover_s = False, 0.05
    assert handover.fade_for(0.1, 0.8) == POSTURE_FADE_S


def test_the_deviation_hands_over_inside_the_backups_basin() -> None:
    zeros = np.zeros((2, 1))
    plan = Plan(zeros, zeros[:1], np.zeros(1), "solved", 0.0, False)

    bound = load_pair_description("cassie", "hovershoes").mpc.handover_deviation

    def at(level: float) -> str | None:
        check = HandoverCheck(plan, 0.0, level, False, True, DivergentDeviation())
        return Deviated(bound)(check)

    assert at(1.75) is None  # the library's largest: its manoeuvres ride on
    assert at(1.25 * 1.75) is None
    assert at(2.9) is not None  # at 3.0 the handed PD stood in 4 rides of 18: before that


def test_a_handover_from_sent_blends_out_of_the_command_sent_not_the_unfit_ticks() -> None:
    """With ``from_sent`` the failing tick's own command (a plan solved from a state past the
    model's edge: knee torques 200 N m off the last tick's on the Segway) never reaches the
    motors: the blend starts from what they hold, so no field of the command steps."""
    handover = Handover(_Backup(), from_sent=True)  # type: ignore[arg-type]
    sent = []
    for k in range(20):
        sensors = SimpleNamespace(time=k * DT, joint_position=np.ones(3))
        failure, primary = ("deviated", _command(-50.0)) if k == 10 else (None, _command(0.0))
        sent.append(handover.step(sensors, None, primary, failure, False))  # type: ignore[arg-type]
    torque = np.array([c.torque[0] for c in sent])
    np.testing.assert_allclose(torque[:11], 0.0, atol=1e-6)  # the handover's tick: the last sent
    assert np.all(np.diff(torque) >= 0.0) and np.all(np.diff(torque) <= DT / BLEND_S + 1e-9)
