"""The motor drivers: a joint PD with feedforward, run at the physics rate, as on the robots.

Controllers send a :class:`MotorCommand` at their own rate; between commands each driver
keeps computing

.. math:: \\tau_k = \\mathrm{clip}\\big(\\tau_{ff} + k_p (q^* - q_k) + k_d (\\dot q^* - \\dot q_k),
          \\; \\pm\\tau_{lim}(\\dot q_k)\\big)

[N m, joint side] from its own encoder at physics step :math:`k`, clipped to the motor's
torque-speed curve (:class:`~ridempc.robots.motor_curve.TorqueSpeedCurve`), and the joint
receives :math:`\\tau_{k-d}`: each motor's ``torque_delay`` in whole physics steps :math:`d`,
never shorter than the delay (3 ms is 5 steps at 1500 Hz). The curve is applied at the speed
the command was computed at, then the torque waits in the delay line, as in Agility's
simulator (``motor()`` in cassie-mujoco-sim's ``cassiemujoco.c``). MuJoCo's motor takes the
motor-side torque ``tau / gear``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.robots.motor_curve import TorqueSpeedCurve
from ridempc.robots.robot import Motor

__all__ = ["MotorCommand", "MotorDriver", "delay_steps"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MotorCommand:
    """Per-motor targets, in actuator order (all joint side).

    Attributes:
        torque: Feedforward torque [N m].
        position: Position target [rad].
        velocity: Velocity target [rad/s].
        kp: Stiffness [N m / rad].
        kd: Damping [N m s / rad].
    """

    torque: Array
    position: Array
    velocity: Array
    kp: Array
    kd: Array

    @classmethod
    def hold(cls, motors: tuple[Motor, ...], position: Array) -> MotorCommand:
        """A pure PD hold of ``position`` with each motor's default gains."""
        n = len(motors)
        return cls(
            torque=np.zeros(n),
            position=np.asarray(position, dtype=float),
            velocity=np.zeros(n),
            kp=np.array([m.kp for m in motors]),
            kd=np.array([m.kd for m in motors]),
        )

    def is_finite(self) -> bool:
        # the five arrays in one test: five isfinite().all() took 5 us a tick, this 1.5
        values = np.concatenate((self.torque, self.position, self.velocity, self.kp, self.kd))
        return bool(np.logical_and.reduce(np.isfinite(values)))


def delay_steps(delay: float, timestep: float) -> int:
    """A delay [s] in whole physics steps of ``timestep`` [s], rounded up (a delay that is a
    whole number of steps, up to float rounding, stays that number)."""
    return max(0, math.ceil(delay / timestep - 1e-9))


def _indexer(index: NDArray[np.int64]) -> NDArray[np.int64] | slice:
    """``index`` as a slice where it is a run of consecutive entries (a quadruped's joints
    and every robot's actuators: read and written as views, three times a control tick,
    not gathered), else as it is."""
    index = np.asarray(index, dtype=np.int64)
    if index.size and np.array_equal(index, np.arange(index[0], index[0] + index.size)):
        return slice(int(index[0]), int(index[0]) + index.size)
    return index


class MotorDriver:
    """Applies the latest :class:`MotorCommand` at every physics step.

    Args:
        model: Compiled scene (its timestep sets the delay in steps).
        motors: The robot's motors.
        actuator_ids: Their actuator ids in the scene.

    Attributes:
        command: The latest command, or None (no torque).
        curve: The motors' torque-speed curves.
        delay: Each motor's torque delay [physics steps].
        demand: The torque the last step's PD and feedforward asked for [N m].
        available: The curve's limit at the last step's joint speeds [N m].
    """

    def __init__(
        self, model: mujoco.MjModel, motors: tuple[Motor, ...], actuator_ids: NDArray[np.int64]
    ) -> None:
        joint_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, m.joint) for m in motors]
        self._qpos = _indexer(np.array([model.jnt_qposadr[j] for j in joint_ids]))
        self._dof = _indexer(np.array([model.jnt_dofadr[j] for j in joint_ids]))
        self._actuators = _indexer(np.asarray(actuator_ids))
        self._gear = np.array([m.gear for m in motors])
        self.curve = TorqueSpeedCurve.of(motors)
        step = float(model.opt.timestep)
        self.delay = np.array([delay_steps(m.torque_delay, step) for m in motors], dtype=np.int64)
        # the delay line: row k % len holds the torques the joints receive at step k, each
        # motor's written ``delay`` rows ahead when computed (read whole: one row, where
        # gathering each motor's own past row took three index operations)
        length = int(self.delay.max()) + 1
        self._line = np.zeros((length, len(motors)))
        self._writes = [
            np.ravel_multi_index(
                ((slot + self.delay) % length, np.arange(len(motors))), (length, len(motors))
            )
            for slot in range(length)
        ]
        self._step = 0
        self._applied = np.zeros(len(motors))
        self.demand = np.zeros(len(motors))
        self.available = self.curve.peak.copy()
        self.command: MotorCommand | None = None

    def reset(self) -> None:
        """Empty the delay line and forget the command (the peak torques are kept)."""
        self._line[:] = 0.0
        self._step = 0
        self._applied[:] = 0.0
        self.demand[:] = 0.0
        self.available[:] = self.curve.peak
        self.command = None

    def torque(self, data: mujoco.MjData) -> Array:
        """Joint-side torque the joints receive now [N m] (set by the last :meth:`apply`)."""
        return self._applied.copy()

    def apply(self, data: mujoco.MjData) -> None:
        """One physics step: compute this step's torque and give the joints the delayed one."""
        cmd = self.command
        qd = data.qvel[self._dof]
        if cmd is None:
            self.demand[:] = 0.0
        else:
            q = data.qpos[self._qpos]
            self.demand = cmd.torque + cmd.kp * (cmd.position - q) + cmd.kd * (cmd.velocity - qd)
        self.available = self.curve.limit(qd)
        slot = self._step % len(self._line)
        # min(max()) rather than np.clip, whose wrapper cost 3 of the old 15 us per call
        self._line.put(
            self._writes[slot],
            np.minimum(np.maximum(self.demand, -self.available), self.available),
        )
        self._applied = self._line[slot].copy()
        self._step += 1
        data.ctrl[self._actuators] = self._applied / self._gear

    def scale_torque_limit(self, scale: float) -> None:
        """Scale every motor's peak torque by ``scale`` (the curve's speeds unchanged)."""
        self.curve = self.curve.scaled(scale)
