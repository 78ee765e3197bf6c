"""The held speed's outer loop over the re-pushes (``mpc/push_speed.py``) and a re-push's
reference anchored at its first push (``mpc/push_gain.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.manoeuvre import REPUSH, REPUSH_BAND, Manoeuvre, ManoeuvreSelector
from ridempc.mpc.push_gain import PushAnchor, ground_time
from ridempc.mpc.push_speed import (
    GAIN_LIMIT,
    INTEGRAL_TIME,
    ROLLING_DECELERATION,
    STROKE_PERIOD,
    StrokeSpeedLoop,
)
from ridempc.mpc.reference import select_reference
from ridempc.scenarios.scenario import Command
from ridempc.trajopt.schedule import Contact

TICK = 0.03  # [s] the MPC's period
CYCLE_MEAN = 0.7 - REPUSH_BAND / 2  # [m/s] what the re-pushes alone hold at 0.7 m/s


def _stride(loop: StrokeSpeedLoop, speeds, start: float = 0.0) -> float:
    """The board's ``speeds`` over one stride from ``start`` [s], closed by a re-push at
    0.7 m/s; the loop's gain."""
    now = start
    for speed in speeds:
        loop.observe(now, float(speed))
        now += TICK
    return loop.stride(now, 0.7)


def test_a_held_speed_cycling_through_its_band_asks_nothing() -> None:
    """Coasting from the command down to the rolling start and pushed back up, stride
    after stride, the board averages the command less half the band: the loop stays idle."""
    loop = StrokeSpeedLoop()
    cycle = 0.7 - REPUSH_BAND * (0.5 - 0.5 * np.cos(2 * np.pi * np.arange(120) / 120))
    for k in range(5):
        assert _stride(loop, cycle, 3.6 * k) == pytest.approx(0.0, abs=1e-3)
    assert loop.integral == pytest.approx(0.0, abs=1e-3)


def test_a_stride_that_falls_short_is_asked_back_with_its_integral() -> None:
    """A stride 0.05 m/s short of the cycle's mean asks a re-push for that shortfall (the
    proportional part) plus the shortfall integrated over the stride at the strokes'
    period; a second one adds to the integral; with no speed seen nothing changes."""
    loop = StrokeSpeedLoop()
    assert loop.stride(1.0, 0.7) == 0.0 and loop.integral == 0.0  # no speed seen yet
    steps = round(1.2 / TICK)
    gain = _stride(loop, [CYCLE_MEAN - 0.05] * steps, 1.0)
    integral = 0.05 * steps * TICK / INTEGRAL_TIME
    assert loop.integral == pytest.approx(integral)
    assert gain == pytest.approx(0.05 + integral)
    _stride(loop, [CYCLE_MEAN - 0.05] * steps, 2.2)
    assert loop.integral == pytest.approx(2 * integral)


def test_the_loop_is_bounded_by_a_strokes_rolling_loss_and_never_brakes() -> None:
    assert GAIN_LIMIT == pytest.approx(ROLLING_DECELERATION * STROKE_PERIOD)
    loop = StrokeSpeedLoop()
    for k in range(3):  # far short for three strides: saturated, not wound up
        assert _stride(loop, [0.2] * 120, 3.6 * k) == pytest.approx(GAIN_LIMIT)
    assert loop.integral == pytest.approx(GAIN_LIMIT)
    assert _stride(loop, [0.9] * 120, 10.8) == 0.0  # faster: coasts, nothing asked
    assert loop.integral >= 0.0
    loop.reset()
    assert loop.mean is None and loop.gain == 0.0 and loop.integral == 0.0


def test_a_short_ride_is_pushed_again_sooner_and_asked_for_more() -> None:
    selector = ManoeuvreSelector("cyberdog2", "skateboard")
    selector.holds_speed = True
    coasting, command = Manoeuvre("accelerate", 0.7, 0.5), Command(velocity=0.7)
    board = 0.7 - REPUSH_BAND + 0.05
    assert selector.repush(command, coasting, 9.0, board) is coasting
    pushed = selector.repush(command, coasting, 9.0, board, gain=0.1)
    assert (pushed.kind, pushed.target, pushed.gain) == (REPUSH, 0.7, 0.1)


def test_ground_time_counts_only_the_feet_on_the_ground() -> None:
    reference = select_reference("cyberdog2", "skateboard", REPUSH, 0.7)
    pushes = [p.duration for p in reference.phases if Contact.GROUND in p.contacts]
    times = np.array([0.0, reference.duration / 2, reference.duration, reference.duration + 1])
    ground = ground_time(reference, times)
    assert ground[0] == 0.0 and ground[2] == ground[3] == pytest.approx(sum(pushes))
    assert np.all(np.diff(ground) >= 0.0)


FAST = 10.0  # [m/s] a held speed no node comes near: the ceiling never binds


def _flat(times: np.ndarray, speed: float) -> np.ndarray:
    """The entry's board speed at the nodes, ``speed`` [m/s] at each."""
    return np.full(len(times), speed)


def _pushing_times(reference, n: int = 30, dt: float = 0.05) -> np.ndarray:
    first = next(
        sum(p.duration for p in reference.phases[:k])
        for k, p in enumerate(reference.phases)
        if Contact.GROUND in p.contacts
    )
    return first + dt * np.arange(n + 1)


def test_an_anchored_repush_with_no_shortfall_is_the_plain_shift() -> None:
    reference = select_reference("cyberdog2", "skateboard", REPUSH, 0.7)
    times = _pushing_times(reference)
    anchor = PushAnchor()
    np.testing.assert_array_equal(
        anchor.extra(reference, times, _flat(times, 0.5), 0.45, 0.0, FAST), 0.0
    )
    later = times + 0.3  # the board as the entry planned it from the anchor: 0.05 below
    np.testing.assert_allclose(
        anchor.extra(reference, later, _flat(later, 0.6), 0.55, 0.0, FAST), 0.0
    )


def test_a_stroke_that_fell_short_is_asked_back_over_the_ground_time_left() -> None:
    """Anchored 0.05 m/s below the entry, the board 0.1 m/s further behind later: node 0
    stays the board's, and the 0.1 m/s is asked back by the end of the last push (at most
    the loop's bound), only while a foot is on the ground."""
    reference = select_reference("cyberdog2", "skateboard", REPUSH, 0.7)
    times = _pushing_times(reference)
    anchor = PushAnchor()
    anchor.extra(reference, times, _flat(times, 0.5), 0.45, 0.0, FAST)
    later = times + 0.3
    extra = anchor.extra(reference, later, _flat(later, 0.6), 0.45, 0.0, FAST)
    assert extra[0] == 0.0 and np.all(np.diff(extra) >= -1e-12)
    ground = ground_time(reference, later)
    left = ground_time(reference, np.array([reference.duration]))[0] - ground[0]
    np.testing.assert_allclose(extra, 0.1 * (ground - ground[0]) / left, atol=1e-12)
    flat = np.diff(ground) == 0.0  # no foot on the ground: nothing more asked
    np.testing.assert_allclose(np.diff(extra)[flat], 0.0, atol=1e-12)
    far = anchor.extra(reference, later, _flat(later, 0.6), 0.0, 0.0, FAST)
    assert far.max() <= GAIN_LIMIT + 1e-12


def test_the_loops_gain_is_laid_over_the_entrys_ground_time() -> None:
    """From the anchor, ``u`` is added as the feet on the ground add momentum: all of it
    by the end of the last push."""
    reference = select_reference("cyberdog2", "skateboard", REPUSH, 0.7)
    start = _pushing_times(reference)[0]
    times = start + 0.05 * np.arange(int((reference.duration - start) / 0.05) + 1)
    extra = PushAnchor().extra(reference, times, _flat(times, 0.5), 0.5, 0.1, FAST)
    assert extra[0] == 0.0 and extra[-1] == pytest.approx(0.1)
    ground = ground_time(reference, times)
    np.testing.assert_allclose(extra, 0.1 * (ground - ground[0]) / (ground[-1] - ground[0]))


def test_the_anchor_never_asks_a_board_past_the_held_speed_and_the_loops_gain() -> None:
    """An entry laid to overshoot its target in its last stroke is not asked back on top:
    where the plain shift already reaches the held speed and the gain nothing is added,
    below it the anchor adds up to that ceiling."""
    reference = select_reference("cyberdog2", "skateboard", REPUSH, 0.7)
    times = _pushing_times(reference)
    anchor = PushAnchor()
    entry = np.linspace(0.5, 0.9, len(times))  # the entry rising past 0.7
    anchor.extra(reference, times, entry, 0.5, 0.1, 0.7)
    later = anchor.extra(reference, times + 0.3, entry, 0.4, 0.1, 0.7)
    plain = entry + 0.4 - 0.5
    assert np.all(plain + later <= np.maximum(0.8, plain) + 1e-12)
    assert later.max() > 0.0 and np.all(later >= 0.0)
