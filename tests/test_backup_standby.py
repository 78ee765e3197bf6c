"""A backup law's standby tick (``Controller.standby``, ``ridempc.mpc.handover``): its state
advanced without its command, so that its next update's command is the one a law updated in
full at every tick gives, to the bit. A short ride (no timing). The roll error's integral is
the one state a standby holds rather than advances (another law rolls the deck then; tested
in ``tests/test_quadruped_skateboard.py``), so here its gain is zero."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.baselines.quadruped_skateboard import QuadrupedSkateboardPD
from ridempc.baselines.quadruped_skateboard_gains import (
    QuadrupedSkateboardGains,
    gains_file,
    load_quadruped_skateboard_gains,
)
from ridempc.boards import load_board
from ridempc.robots import load_robot
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation

EVERY = 7  # [ticks] the twin's full updates; standby on the ticks between


def _without_integral(robot: str, board: str) -> QuadrupedSkateboardGains:
    """The pair's PD gains with the roll error's integral switched off."""
    gains = load_quadruped_skateboard_gains(gains_file(robot, board))
    return gains.model_copy(update={"roll": gains.roll.model_copy(update={"ki": 0.0})})


class _WithTwin(QuadrupedSkateboardPD):
    """The PD riding, and a twin fed the same packets: in standby, and updated in full every
    :data:`EVERY` ticks, its commands then kept beside the rider's."""

    def __init__(self, robot, board: str) -> None:
        gains = _without_integral(robot.name, board)
        super().__init__(robot, board, gains)
        self.twin = QuadrupedSkateboardPD(robot, board, gains)
        self.ticks = 0
        self.pairs: list = []

    def update(self, sensors, command):
        out = super().update(sensors, command)
        if self.ticks % EVERY == 0:
            self.pairs.append((out, self.twin.update(sensors, command)))
        else:
            self.twin.standby(sensors, command)
        self.ticks += 1
        return out


@pytest.mark.parametrize("robot", ["cyberdog2", "go1"])
def test_the_quadruped_pds_standby_keeps_its_commands_to_the_bit(robot: str) -> None:
    dog = load_robot(robot)
    scenario = resolve_scenario("roll-tracking", "skateboard").with_duration(0.6)
    scene = build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
    controller = _WithTwin(dog, "skateboard")
    result = Simulation(scene, controller, scenario).run()
    assert result.status == "ok", result.fall_reason or result.error
    assert len(controller.pairs) > 20
    for riding, twin in controller.pairs:
        for name in ("torque", "position", "velocity", "kp", "kd"):
            np.testing.assert_array_equal(getattr(twin, name), getattr(riding, name), name)
    assert controller.twin._shift == controller._shift  # the roll's filters, too
    assert controller.twin._shift != (0.0, 0.0)
