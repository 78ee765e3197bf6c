"""The posture fade left out for a handover in a start's first divergence time
(ridempc/mpc/start_fade.py)."""

from __future__ import annotations

import math

import pytest

from ridempc.mpc.divergence import GRAVITY
from ridempc.mpc.handover import POSTURE_FADE_S, Fallback, Handover
from ridempc.mpc.start_fade import StartFade, start_window


def _handover() -> Handover:
    return Handover(backup=object())  # type: ignore[arg-type]  # the backup is not run here


def test_the_window_is_the_riders_divergence_time() -> None:
    # Cassie's centre of mass 0.8 m over her feet: 1/omega = sqrt(0.8/9.81) = 0.286 s
    assert start_window(0.8) == pytest.approx(math.sqrt(0.8 / GRAVITY))
    assert start_window(0.8) == pytest.approx(0.2856, abs=1e-4)
    # a taller rider diverges slower: a longer window
    assert start_window(1.2) > start_window(0.8)
    # a height not yet measured gives no empty window
    assert start_window(0.0) == pytest.approx(math.sqrt(0.1 / GRAVITY))


def test_a_handover_in_the_first_divergence_time_takes_no_fade() -> None:
    handover = _handover()
    fade = StartFade(handover)
    assert fade(0.0, 0.8) == 0.0
    assert fade(0.064, 0.8) == 0.0  # the Segway's start handovers
    assert handover.fade_s == 0.0
    assert fade(0.3, 0.8) == POSTURE_FADE_S  # past 0.286 s: a posture the plan chose
    assert handover.fade_s == POSTURE_FADE_S


def test_the_window_counts_from_the_rides_first_tick() -> None:
    fade = StartFade(_handover())
    fade(10.0, 0.8)
    assert fade(10.2, 0.8) == 0.0
    assert fade(10.3, 0.8) == POSTURE_FADE_S


def test_only_the_first_handover_and_only_a_start_on_the_primary() -> None:
    handover = _handover()
    fade = StartFade(handover)
    handover.fallbacks.append(Fallback(0.05, "deviation", duration_s=0.01))
    assert fade(0.1, 0.8) == POSTURE_FADE_S  # a second handover: the configured fade

    backup_start = _handover()
    backup_start.start_on_backup()
    fade = StartFade(backup_start)
    assert fade(0.0, 0.8) == POSTURE_FADE_S  # the primary's posture at takeover is the backup's
    backup_start.starting, backup_start.takeover_s = False, 0.1
    assert fade(0.15, 0.8) == POSTURE_FADE_S


def test_a_configured_fade_is_kept_outside_the_window() -> None:
    handover = Handover(backup=object(), fade_s=0.2)  # type: ignore[arg-type]
    fade = StartFade(handover)
    assert fade(0.0, 0.8) == 0.0
    assert fade(1.0, 0.8) == 0.2
