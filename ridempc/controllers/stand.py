"""``stand``: hold the posture the robot starts in with each motor's joint PD.

The simplest controller, to show the loop working. At the first tick it reads the motor
joints' encoders (the robot starts in its description's stand keyframe, or its stance
keyframe for the board) and from then on holds them with the robot's default low-level
gains, :math:`\\tau = k_p (q_0 - q) - k_d \\dot q` [N m]. It does not balance: it stands
only where that posture's centre of mass is over the feet.

It also runs the state estimator (:class:`~ridempc.estimation.StateEstimator`), without
using it, so that every ride reports the estimator's error. On a board, every foot is
taken to stand on one platform.
"""

from __future__ import annotations

import numpy as np

from ridempc.boards import support_height
from ridempc.controllers.base import Controller
from ridempc.estimation import EstimatedState, StateEstimator
from ridempc.robots.robot import Robot
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = ["StandController"]


class StandController(Controller):
    rate_hz = 500.0

    def __init__(self, robot: Robot, board: str = "none") -> None:
        super().__init__(robot, board)
        self._hold: MotorCommand | None = None
        feet = robot.params.foot_bodies
        self.estimator = StateEstimator(
            robot,
            platforms=(feet,) if board != "none" else (),
            support_height=support_height(board),
        )

    def reset(self, sensors: SensorPacket) -> None:
        n = len(self.robot.motors)  # the motor joints lead the encoder list
        self._hold = MotorCommand.hold(self.robot.motors, np.array(sensors.joint_position[:n]))
        self.estimator.reset(sensors)

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        if self._hold is None:
            self.reset(sensors)
        assert self._hold is not None
        self.estimator.update(sensors)
        return self._hold

    def estimate(self) -> EstimatedState | None:
        return self.estimator.state
