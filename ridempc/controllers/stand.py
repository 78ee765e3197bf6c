"""``stand``: hold the standing keyframe with each motor's joint PD.

The simplest controller, to show the loop working: the motor targets are the
description's ``stand`` keyframe and the gains are the robot's default low-level gains,
:math:`\\tau = k_p (q_{stand} - q) - k_d \\dot q` [N m]. It uses no sensor but the
encoders the drivers already read, and it does not balance: it stands only where the
keyframe's centre of mass is over the feet.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ridempc.controllers.base import Controller
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = ["StandController"]


class StandController(Controller):
    rate_hz = 500.0

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        model = robot.mj_model
        qpos = robot.stand_qpos
        targets = []
        for motor in robot.motors:
            joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, motor.joint)
            targets.append(qpos[model.jnt_qposadr[joint]])
        self._hold = MotorCommand.hold(robot.motors, np.array(targets))

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        return self._hold
