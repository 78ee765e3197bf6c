"""A slow board's re-push stroke is not handed to the balancing backup for its deviation
alone, and a push handed over is blended over the rider's divergence time
(:mod:`ridempc.mpc.push_handover`)."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from ridempc.mpc.handover import BLEND_S, Handover
from ridempc.mpc.push_handover import deviation_deferred, push_blend
from ridempc.pair_description import load_pair_description
from ridempc.sim.motors import MotorCommand
from ridempc.trajopt.schedule import Contact

B, G, S = Contact.BOARD, Contact.GROUND, Contact.SWING
START = 0.5  # [m/s] the stride's rolling start


def test_a_slow_boards_re_push_with_a_foot_off_the_deck_rides_its_stroke_out() -> None:
    assert deviation_deferred(True, (B, B, G, B), 0.3, START)  # pushing on the ground
    assert deviation_deferred(True, (B, B, B, S), 0.3, START)  # swinging back to the deck


def test_a_board_at_its_strides_rolling_start_is_judged_as_before() -> None:
    assert not deviation_deferred(True, (B, B, B, S), START, START)
    assert not deviation_deferred(True, (B, B, B, S), 0.7, START)


def test_every_foot_on_the_deck_is_judged_as_before() -> None:
    assert not deviation_deferred(True, (B, B, B, B), 0.3, START)


def test_other_manoeuvres_and_a_rider_before_its_first_plan_are_judged_as_before() -> None:
    assert not deviation_deferred(False, (B, B, G, B), 0.3, START)  # the push-off from rest
    assert not deviation_deferred(True, None, 0.3, START)


DT = 0.002  # [s] the rider's tick


def _command(value: float) -> MotorCommand:
    return MotorCommand(*(np.full(3, value) for _ in range(5)))


class _Backup:
    """A backup law whose knee feedforward is 1 (the primary's 0)."""

    def update(self, sensors: Any, command: Any) -> MotorCommand:
        return _command(1.0)


def test_a_push_is_blended_over_the_riders_divergence_time() -> None:
    height = 0.9  # [m] Cassie's centre of mass over her feet
    blend = push_blend(height, BLEND_S)
    assert blend == pytest.approx(math.sqrt(height / 9.81))  # 0.30 s, 15x the usual
    assert push_blend(None, BLEND_S) == BLEND_S  # no height measured yet: the usual blend
    handover = Handover(_Backup(), fade_s=0.0)  # type: ignore[arg-type]
    sent = []
    for k in range(200):
        sensors = SimpleNamespace(time=k * DT, joint_position=np.zeros(3))
        failure = "pushed" if k >= 10 else None
        step = handover.step(sensors, None, _command(0.0), failure, False, height, blend)  # type: ignore[arg-type]
        sent.append(step.torque[0])
    # the torque the push shifted moves back at a steady rate, 1/blend per second
    rise = round(blend / DT)
    np.testing.assert_allclose(sent[10 : 10 + rise], np.arange(rise) / (blend / DT), atol=1e-6)
    assert sent[10 + rise + 1] == 1.0


def test_the_push_blend_is_the_hovershoes_pairs_and_no_other() -> None:
    for board, blended in (("hovershoes", True), ("segway", False)):
        impulse = load_pair_description("cassie", board).stages.impulse
        assert impulse is not None and impulse.divergence_blend is blended
