"""The controller ticks sorted by their place in the MPC's period (synthetic ticks: no ride,
no timing)."""

from __future__ import annotations

import math

import numpy as np

from ridempc.tickphases import tick_phases


def test_the_periodic_ticks_are_named_and_left_out_of_the_steady_p99() -> None:
    period, rate = 15, 500.0
    seconds = np.full(3 * 500, 0.5e-3)  # 3 s of 0.5 ms ticks
    seconds[::period] = 4e-3  # the MPC's tick
    seconds[2::period] = 1e-3  # the take-up, two ticks on
    seconds[7::period] = 2e-3  # the standby
    seconds[:500] += 1e-3  # the first second: the standby every tick
    figures = tick_phases(seconds, period, {"mpc_tick": 0, "take_up": 2, "standby": 7}, rate, 1.0)
    assert math.isclose(figures["mpc_tick_median"], 4.0)
    assert math.isclose(figures["take_up_median"], 1.0)
    assert math.isclose(figures["standby_median"], 2.0)
    assert math.isclose(figures["phase_5_median"], 0.5)
    assert math.isclose(figures["steady_p99"], 0.5)  # the periodic ticks and the warm-up out
    assert math.isclose(figures["steady_median"], 0.5)
    # with the take-up in the MPC's tick (no latency), it has no tick of its own
    figures = tick_phases(seconds, period, {"mpc_tick": 0, "take_up": None}, rate, 1.0)
    assert math.isnan(figures["take_up_median"])
    assert math.isclose(figures["steady_p99"], 2.0)  # the standby's ticks now count


def test_a_ride_shorter_than_the_warmup_has_no_figures() -> None:
    figures = tick_phases([1e-3] * 10, 15, {"mpc_tick": 0}, 500.0, 1.0)
    assert math.isnan(figures["mpc_tick_median"]) and math.isnan(figures["steady_p99"])
