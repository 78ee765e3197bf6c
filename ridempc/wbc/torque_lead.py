"""The whole-body QP's torques led over the motors' delay: sent as they will be when they arrive.

A motor with a torque delay :math:`T` (:class:`~ridempc.sim.motors.MotorDriver`) applies the
torque it is sent :math:`T` later, so a QP that computes :math:`\\tau(t)` from the state at
:math:`t` acts on the joints with :math:`\\tau(t - T)`: its loop through the robot and the
board loses :math:`\\omega T` of phase at every frequency :math:`\\omega`, most where its loops
are fast. Sending the QP's torque extrapolated over the delay from its last two ticks,

.. math:: \\tau_{sent}(t) = \\tau(t)
          + \\frac{T}{\\Delta t}\\,\\big(\\tau(t) - \\tau(t - \\Delta t)\\big)
          \\quad [N m],

the first-order prediction of :math:`\\tau(t + T)`, gives that phase back below the tick's
Nyquist frequency (to first order in :math:`\\omega T`): a torque that changes linearly
arrives as the QP would have computed it at its arrival. Each motor is led by its own delay,
so a motor without one is sent the QP's torque unchanged. No constant is chosen: the lead is
the motors' delay over the QP's tick. Only consecutive ticks count: the first tick, a tick
after a gap (a failed solve) or one solved again at the same time sends the QP's torque.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.robots.robot import Robot

__all__ = ["TorqueLead"]

Array = NDArray[np.float64]


class TorqueLead:
    """Each motor's torque extrapolated over its delay from the QP's last two ticks.

    Args:
        robot: The robot (its motors' torque delays, actuator order).
        dt: The QP's tick :math:`\\Delta t` [s].

    Attributes:
        lead: Per motor, :math:`T / \\Delta t` [-] (0: no delay, the torque is sent as is).
    """

    def __init__(self, robot: Robot, dt: float) -> None:
        self.lead = np.array([m.torque_delay for m in robot.motors], dtype=float) / dt
        self._dt = dt
        self._last: tuple[float, Array] | None = None

    def reset(self) -> None:
        """Forget the last tick (the next torque is sent as the QP computed it)."""
        self._last = None

    def __call__(self, time: float, torque: Array) -> Array:
        """The torque to send at ``time`` [s] for the QP's ``torque`` [N m] (actuator order)."""
        last, self._last = self._last, (time, np.array(torque, dtype=float))
        if not self.lead.any() or last is None:
            return torque
        before, previous = last
        if abs(time - before - self._dt) > 0.5 * self._dt:  # not the tick after
            return torque
        return torque + self.lead * (torque - previous)
