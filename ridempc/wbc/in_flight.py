"""The torques still on their way to the joints, and the hold a line foot needs against them.

A motor with a torque delay :math:`T` (:class:`~ridempc.sim.motors.MotorDriver`) applies, over
the next :math:`T`, the torques the QP asked for in the last :math:`T`: the QP's new torque
reaches the joint only after them. The QP models a line foot (two contact sites) as held flat
on its support by both sites, so the torque of the motor that turns the foot (Cassie's toe)
is balanced by the two sites' normal forces, :math:`\\Delta f = \\Delta\\tau / \\ell` across the
sites' lever :math:`\\ell` [m]. While the torques in flight differ from the one the QP plans
with by :math:`\\Delta\\tau`, the foot stays flat only if each site keeps

.. math:: f_{n,s} \\ge \\frac{\\max_i \\tau_i - \\min_i \\tau_i}{\\ell} \\quad [N],

the spread of the foot motor's torques over the last :math:`\\lceil T / \\Delta t \\rceil + 1`
ticks before this one (those in flight and the one arriving) over the lever; a site at zero
force is a foot at its tipping point, where the foot's joint loop through the delay has no
margin. Each site's bound is at most half its foot's planned normal force, the most that
both sites can carry at once. Without a delay nothing is in flight and no site is bounded.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from numpy.typing import NDArray

from ridempc.robots.robot import Robot
from ridempc.wbc.model import WholeBodyModel

__all__ = ["TorquesInFlight"]

Array = NDArray[np.float64]
Index = NDArray[np.int64]


class TorquesInFlight:
    """The QP's last torques, and each contact site's least normal force against them.

    Args:
        model: The WBC's model (its line feet and their sites).
        robot: The robot (its motors' torque delays).
        dt: The QP's tick [s].

    Attributes:
        window: How many ticks' torques count [-] (0: no delay, nothing in flight).
        site_motor: Per contact site, the motor that turns its line foot (-1: none).
        site_lever: Per contact site, the distance between its foot's two sites [m].
    """

    def __init__(self, model: WholeBodyModel, robot: Robot, dt: float) -> None:
        delay = max((m.torque_delay for m in robot.motors), default=0.0)
        self.window = math.ceil(delay / dt - 1e-9) + 1 if delay > 0.0 else 0
        n_sites = len(model.site_frames)
        self.site_motor: Index = np.full(n_sites, -1, dtype=np.int64)
        self.site_lever = np.zeros(n_sites)
        self.site_foot: Index = np.asarray(model.site_foot, dtype=np.int64)
        frames, pin_model = model.model.frames, model.model
        joints = {m.joint: i for i, m in enumerate(robot.motors)}
        for second, first in enumerate(model.site_partner):
            if first < 0:
                continue
            a, b = frames[model.site_frames[first]], frames[model.site_frames[second]]
            motor = joints.get(pin_model.names[a.parentJoint], -1)
            if motor < 0 or a.parentJoint != b.parentJoint:
                continue
            lever = float(np.linalg.norm(a.placement.translation - b.placement.translation))
            self.site_motor[[first, second]] = motor
            self.site_lever[[first, second]] = lever
        self._dt = dt
        # (site, motor, lever, foot) of each site on a line foot: a few per robot, so the
        # bounds are worked out in plain floats, where NumPy's per-call cost dominates
        self._lined = [
            (s, int(self.site_motor[s]), float(self.site_lever[s]), int(self.site_foot[s]))
            for s in np.flatnonzero(self.site_motor >= 0).tolist()
        ]
        self._torques: deque[tuple[float, list[float]]] = deque(maxlen=max(self.window, 1))

    def record(self, time: float, torque: Array) -> None:
        """Keep the motor torques [N m] (actuator order) the QP asked for at ``time`` [s]."""
        if self.window:
            self._torques.append((time, np.asarray(torque, dtype=float).tolist()))

    def least_forces(self, time: float, foot_normal_forces: Array) -> Array | None:
        """Each contact site's least normal force at ``time`` [s] [N], or None (no bound).

        Only the torques of the ``window`` ticks before ``time`` count (half a tick either
        side): a QP solved again at the same time, or after a gap, has none in flight.

        Args:
            time: This tick's time [s].
            foot_normal_forces: Each foot's planned normal force [N].
        """
        earliest, latest = time - (self.window + 0.5) * self._dt, time - 0.5 * self._dt
        recent = [tau for t, tau in self._torques if earliest <= t <= latest]
        if len(recent) < 2 or not self._lined:
            return None
        forces = np.asarray(foot_normal_forces, dtype=float).tolist()
        least = [0.0] * len(self.site_motor)
        for site, motor, lever, foot in self._lined:
            torques = [tau[motor] for tau in recent]
            spread = (max(torques) - min(torques)) / lever
            least[site] = min(spread, 0.5 * max(forces[foot], 0.0))
        return np.array(least)
