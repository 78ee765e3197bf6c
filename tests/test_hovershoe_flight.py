"""The hovershoe rider's flight detector: a foot unloaded when its shin spring relaxes."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.baselines.hovershoe_flight import unloaded_feet
from ridempc.baselines.hovershoe_gains import FlightGains, load_hovershoes_gains
from ridempc.errors import ConfigError


def test_standing_deflection_is_loaded_and_relaxed_spring_unloaded() -> None:
    flags = unloaded_feet(np.array([-0.039, -0.004]), 0.012)
    assert flags.tolist() == [False, True]


def test_zero_threshold_never_unloads() -> None:
    assert not unloaded_feet(np.array([0.0, -0.0001]), 0.0).any()


def test_gain_file_sets_flight_and_default_is_off() -> None:
    gains = load_hovershoes_gains()
    assert 0.0 < gains.flight.unloaded_shin < 0.039  # below the standing deflection
    assert FlightGains().unloaded_shin == 0.0


def test_negative_threshold_is_refused() -> None:
    with pytest.raises((ConfigError, ValueError)):
        FlightGains(unloaded_shin=-0.01)
