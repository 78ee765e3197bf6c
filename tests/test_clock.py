"""Rates are whole numbers of physics steps, exact in simulation time."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ, Rate
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation
from tests.helpers import RecordingController, scenario


def test_default_rates_divide_the_physics_rate() -> None:
    assert Rate.of(500, DEFAULT_PHYSICS_HZ).period == 3
    assert Rate.of(30, DEFAULT_PHYSICS_HZ).period == 50
    assert Rate.of(DEFAULT_PHYSICS_HZ, DEFAULT_PHYSICS_HZ).period == 1


@pytest.mark.parametrize("hz", [7.0, 0.0, -30.0, 2000.0, 400.0])
def test_rates_that_do_not_divide_are_refused(hz: float) -> None:
    with pytest.raises(ConfigError, match="rate"):
        Rate.of(hz, DEFAULT_PHYSICS_HZ)


def test_controller_runs_exactly_at_its_rate(robot) -> None:
    controller = RecordingController(robot)
    sim = Simulation(build_scene(robot, DEFAULT_PHYSICS_HZ), controller, scenario(1.0))
    result = sim.run()
    assert result.status == "ok"
    stamps = np.array([p.time for p in controller.packets])
    assert len(stamps) == 500  # 1 s at 500 Hz, the update at t = 1 s is not run
    assert np.array_equal(stamps, np.arange(500) / 500.0)


def test_vio_is_delayed_and_at_30_hz(robot) -> None:
    controller = RecordingController(robot)
    noise = {"vio_latency": 0.04, "vio_hz": 30.0}
    sim = Simulation(build_scene(robot, DEFAULT_PHYSICS_HZ), controller, scenario(1.0, noise=noise))
    sim.run()
    for packet in controller.packets:
        if packet.vio is None:
            assert packet.time < 0.04
            continue
        lag = packet.time - packet.vio.stamp
        assert 0.04 - 1e-9 <= lag < 0.04 + 1.0 / 30.0
        assert abs(packet.vio.stamp * 30.0 - round(packet.vio.stamp * 30.0)) < 1e-9
