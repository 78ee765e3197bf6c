"""When the MPC takes the ride from the backup it starts on (``ridempc.mpc.readiness``) and the
handover's start (``ridempc.mpc.handover``), on synthetic estimate histories at the MPC's
30 Hz; and one short ride in which the PD holds the start."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from ridempc.mpc.handover import BLEND_S, Handover
from ridempc.mpc.readiness import (
    LONGEST_WAIT,
    MANOEUVRE,
    SETTLED,
    StartReadiness,
    StartRule,
    start_readiness,
)
from ridempc.pair_description import TakeoverStage
from ridempc.sim.motors import MotorCommand

STEP = 1.0 / 30.0  # [s] the MPC's
RULE = StartRule(window=0.3, tolerances=(0.05, 0.005, 0.005), dwell=0.5, longest_wait=2.0)


def _ride(readiness: StartReadiness, estimate, in_band, manoeuvre=lambda t: False) -> float | None:
    """Ticks until ready over 3 s; the time it became ready [s] (None: never)."""
    for k in range(90):
        t = k * STEP
        if readiness.update(t, estimate(t), in_band(t), manoeuvre(t)):
            return t
    return None


def _settling(t: float) -> np.ndarray:
    """A payload of +20 % learnt with a 0.1 s lag from 0.1 s, and an offset creeping in."""
    mass = 0.2 * (1.0 - np.exp(-max(t - 0.1, 0.0) / 0.1))
    shift = 0.03 * (1.0 - np.exp(-t / 0.3))
    return np.array([mass, shift, 0.0])


def test_not_ready_while_the_estimate_moves_ready_once_settled_and_in_band() -> None:
    readiness = StartReadiness(RULE)
    ready = _ride(readiness, _settling, lambda t: True)
    # the mass moves by less than 0.05 over a 0.3 s window from 0.55 s, the offset by less
    # than 5 mm from 0.7 s (0.03 e^{-t/0.3} (e - 1)): not before
    assert ready is not None and 0.68 < ready < 0.75
    assert readiness.reason == SETTLED and readiness.ready_s == ready
    assert readiness.summary() == {"ready_s": ready, "reason": SETTLED}
    assert np.all(readiness.spread <= np.asarray(RULE.tolerances))


def test_settled_but_out_of_the_band_waits_for_the_dwell_in_it() -> None:
    readiness = StartReadiness(RULE)
    ready = _ride(readiness, lambda t: np.zeros(3), lambda t: t >= 0.8)
    assert ready == pytest.approx(0.8 + RULE.dwell, abs=STEP)
    assert readiness.reason == SETTLED
    # a pair without estimates (none given): the band and the dwell alone
    bare = StartReadiness(RULE)
    assert _ride(bare, lambda t: None, lambda t: True) == pytest.approx(RULE.dwell, abs=STEP)


def test_never_stuck_the_longest_wait_with_its_reason() -> None:
    readiness = StartReadiness(RULE)
    moving = lambda t: np.array([0.1 * np.sin(10.0 * t), 0.0, 0.0])  # noqa: E731
    ready = _ride(readiness, moving, lambda t: True)
    assert ready == pytest.approx(RULE.longest_wait, abs=STEP)
    assert readiness.reason == LONGEST_WAIT
    # a NaN estimate restarts the window: never settled, the longest wait again
    nan = StartReadiness(RULE)
    assert _ride(nan, lambda t: np.full(3, np.nan), lambda t: True) == pytest.approx(
        RULE.longest_wait, abs=STEP
    )
    assert nan.reason == LONGEST_WAIT
    # out of the band then: the band is not waived, the dwell in it counts from its entry
    late = StartReadiness(RULE)
    assert _ride(late, moving, lambda t: t >= 2.2) == pytest.approx(2.2 + RULE.dwell, abs=STEP)
    assert late.reason == LONGEST_WAIT
    never = StartReadiness(RULE)
    assert _ride(never, moving, lambda t: False) is None
    assert never.summary() == {
        "ready_s": None,
        "reason": None,
        "waiting_for": "the estimates to settle",
    }


def test_a_commanded_manoeuvre_takes_over_at_once() -> None:
    readiness = StartReadiness(RULE)
    ready = _ride(readiness, _settling, lambda t: False, lambda t: t >= 0.2)
    assert ready == pytest.approx(0.2, abs=STEP) and readiness.reason == MANOEUVRE


def test_the_pair_stage_builds_the_rule() -> None:
    assert start_readiness(None, 0.5) is None
    stage = TakeoverStage(window=0.3, mass_change=0.05, shift_change=0.005, longest_wait=2.0)
    readiness = start_readiness(stage, 0.5)
    assert readiness is not None and readiness.rule == RULE


def _command(value: float) -> MotorCommand:
    return MotorCommand(*(np.full(3, value) for _ in range(5)))


class _Backup:
    def update(self, sensors: Any, command: Any) -> MotorCommand:
        return _command(1.0)


def test_the_handover_holds_the_start_on_the_backup_and_blends_the_takeover() -> None:
    handover = Handover(_Backup())  # type: ignore[arg-type]
    handover.start_on_backup()
    dt, sent = 0.002, []
    for k in range(200):
        sensors = SimpleNamespace(time=k * dt)
        ready = k >= 100
        sent.append(handover.step(sensors, None, _command(0.0), None, ready))  # type: ignore[arg-type]
    torque = np.array([c.torque[0] for c in sent])
    assert np.all(torque[:100] == 1.0)  # the backup holds the start
    ramp = round(BLEND_S / dt)
    np.testing.assert_allclose(torque[100 : 100 + ramp], 1.0 - np.arange(ramp) / ramp, atol=1e-6)
    assert np.all(torque[100 + ramp :] == 0.0)
    assert handover.takeover_s == pytest.approx(0.2)
    assert handover.summary() == []  # the start is no fallback
    assert handover.dwell() == handover.dwell_s  # and does not lengthen the next return's


def test_cassie_starts_on_the_pd_and_the_mpc_takes_over_once_settled() -> None:
    """stand-still on the Hovershoes, no payload: the PD holds the start while the payload
    estimate reads the stance (within its deadband: settled at once) and the MPC's plans
    bring the rider into their return band; the MPC takes over after the dwell and rides
    on, with no fallback."""
    from ridempc.boards import load_board
    from ridempc.mpc.rider import MpcRider
    from ridempc.robots import load_robot
    from ridempc.scenarios import resolve_scenario
    from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
    from ridempc.sim.scene import build_scene
    from ridempc.sim.simulation import Simulation

    cassie = load_robot("cassie")
    rider = MpcRider(cassie, "hovershoes")
    assert rider.handover.starting and rider.handover.on_backup
    scenario = resolve_scenario("stand-still", "hovershoes").with_duration(1.5)
    scene = build_scene(cassie, DEFAULT_PHYSICS_HZ, board=load_board("hovershoes"))
    result = Simulation(scene, rider, scenario).run()
    assert result.status == "ok" and not result.fell
    summary = rider.summary()
    assert summary["takeover"]["reason"] == SETTLED
    assert RULE.dwell <= summary["mpc_takeover_s"] < 1.2
    assert summary["fallbacks"] == [] and not rider.handover.on_backup


def test_the_pair_asks_for_the_proof_by_prediction() -> None:
    """``by_prediction`` is off unless the pair's takeover asks for it."""
    base = {"window": 0.3, "mass_change": 0.05, "shift_change": 0.005, "longest_wait": 2.0}
    plain = start_readiness(TakeoverStage(**base), 0.5)
    asked = start_readiness(TakeoverStage(**base, by_prediction=True), 0.5)
    assert plain is not None and not plain.rule.by_prediction
    assert asked is not None and asked.rule.by_prediction
