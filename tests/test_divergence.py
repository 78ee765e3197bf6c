"""The divergent component of the MPC's deviation (``ridempc.mpc.divergence``), on made-up
deviation histories sampled at the MPC's 30 Hz."""

from __future__ import annotations

import math

import pytest

from ridempc.mpc.divergence import GRAVITY, DivergentDeviation, Probation

STEP = 1.0 / 30.0  # [s] the MPC's tick
HEIGHT = 0.9  # [m] a standing rider's centre of mass over its feet
OMEGA = math.sqrt(GRAVITY / HEIGHT)  # [1/s]


def _ride(measured: list[float], expected: list[float]) -> tuple[DivergentDeviation, float | None]:
    """Each tick: the measured deviation, then the plan's expected one for the next; when
    the divergent component first passes 3."""
    divergence, crossed = DivergentDeviation(), None
    for k, (d, ahead) in enumerate(zip(measured, expected, strict=True)):
        if divergence.update(k * STEP, d, HEIGHT) > 3.0 and crossed is None:
            crossed = k * STEP
        divergence.expect(ahead)
    return divergence, crossed


def test_a_deviation_as_planned_does_not_lead() -> None:
    """A manoeuvre's reference running ahead: the deviation grows as each plan says."""
    measured = [min(0.1 * k, 2.5) for k in range(40)]
    divergence, crossed = _ride(measured, [d + 0.1 for d in measured])
    assert crossed is None
    assert divergence.value == pytest.approx(measured[-1])


def test_a_toppling_rider_leads_by_its_divergence_time() -> None:
    """d = d0 e^(omega t), an unstable pendulum's error, where each plan expects it to hold:
    the divergent component passes the threshold well before the deviation does."""
    measured = [0.2 * math.exp(OMEGA * k * STEP) for k in range(40)]
    divergence, crossed = _ride(measured, measured)
    crossed_d = next(k * STEP for k, d in enumerate(measured) if d > 3.0)
    assert crossed is not None
    assert crossed_d - crossed > 0.5 * math.log(2.0) / OMEGA
    assert 1.5 * measured[-1] < divergence.value < 2.0 * measured[-1]


def test_a_deviation_better_than_planned_does_not_lead() -> None:
    measured = [3.0 * math.exp(-4.0 * k * STEP) for k in range(20)]
    divergence, _ = _ride(measured, [d + 0.2 for d in measured])
    assert divergence.rate < 0.0
    assert divergence.value == pytest.approx(measured[-1])


def test_reset_forgets_the_plan_and_an_uncounted_update_is_no_peak() -> None:
    divergence, _ = _ride([0.0, 1.0, 2.0], [0.0, 0.0, 0.0])
    peak = divergence.peak
    assert peak > 2.0
    divergence.reset()
    assert divergence.update(10.0, 5.0, HEIGHT, counted=False) == pytest.approx(5.0)
    assert divergence.peak == peak


def test_probation_ends_after_a_dwell_fit_and_restarts_on_a_return() -> None:
    probation = Probation()
    assert not probation.update(0.0, True, 0.5)
    assert not probation.update(0.3, False, 0.5)  # unfit: the dwell starts again
    assert not probation.update(0.4, True, 0.5)
    assert probation.update(0.9, True, 0.5)
    assert probation.update(1.0, False, 0.5)  # once proven, until restarted
    probation.restart()
    assert not probation.proven


def test_a_model_missing_every_prediction_is_not_proven_within_the_band() -> None:
    """A wrong model (the board's firmware off its parameters): the deviation stays within
    the return band (0.7), but every plan's one-step prediction (0.5) misses it by the same
    margin, 6/s; the rider is not settled and the MPC stays on probation. The same level
    predicted by its plans settles and is proven after the dwell."""
    for expected, proven in ((0.5, False), (0.7, True)):
        divergence, probation = DivergentDeviation(), Probation()
        for k in range(40):  # 1.3 s, beyond the 0.5 s dwell
            divergence.update(k * STEP, 0.7, HEIGHT)
            divergence.expect(expected)
            probation.update(k * STEP, divergence.settled(1.0, 0.7), 0.5)
        assert divergence.value > 0.7 if not proven else divergence.value == pytest.approx(0.7)
        assert probation.proven is proven


def test_without_the_prediction_the_level_alone_settles() -> None:
    """A pair that proves its MPC by the level alone (``by_prediction`` false) is settled
    within the band whatever its plans predicted; by prediction, not."""
    divergence = DivergentDeviation()
    for k in range(10):
        divergence.update(k * STEP, 0.7, HEIGHT)
        divergence.expect(0.5)  # each plan expects less than it gets: 6/s of surprise
    assert divergence.settled(1.0, 0.7, by_prediction=False)
    assert not divergence.settled(1.0, 0.7)
