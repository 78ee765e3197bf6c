"""Steering through the speed's noise about the least speed (ridempc.mpc.steer_speed)."""

from __future__ import annotations

from ridempc.mpc.steer_speed import SteerSpeed


def test_steering_holds_through_the_band_and_stops_below_it():
    latch = SteerSpeed(0.3, band=0.06)
    assert latch(0.28) == 0.0  # not yet steering: below the least speed is not rolling
    assert latch(0.32) == 0.32
    assert latch(0.27) == 0.3  # noise below the least speed: steered as at it
    assert latch(0.31) == 0.31
    assert latch(0.23) == 0.0  # fallen through the band
    assert latch(0.27) == 0.0  # and not steering again until the least speed
    assert latch(-0.35) == -0.35 and latch(-0.26) == -0.3
