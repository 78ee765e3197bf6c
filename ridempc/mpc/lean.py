"""Turning a Segway by leaning into its knee bar: the MPC rider's crouch and lean loop.

The Segway's firmware turns at :math:`\\dot\\psi_{ref} = k_{turn} \\delta`, with
:math:`\\delta` [rad] the tilt of the knee bar that the rider's shins push (Segway paper,
IV-B: "To turn, Cassie needs to lean into the center bar with her legs, which is
accomplished by shifting :math:`p_y^{CoM}`"). The bar is not in the MPC's model as a push of
the legs: a plan that moved the library's ``knee_bar`` input would count on a push nobody
gives, so the rider holds that input at zero and leans instead, as the ``pd`` baseline
(:mod:`ridempc.baselines.cassie_segway`) does:

1. **Crouch** (:class:`Crouch`). Standing tall, Cassie's shins pass 0.13-0.24 m behind the
   pad. The rider rides in the robot's riding keyframe (``ride_keyframes``): its whole-body
   posture task holds that keyframe's motor angles, and the MPC's centre-of-mass height
   reference is lowered by

   .. math:: \\Delta z = h_{ride} - h_{stance}

   [m], the difference of the two keyframes' centre-of-mass heights over the mean of their
   contact sites (the library was built standing: -0.255 m for Cassie), brought in linearly
   over ``CROUCH_SECONDS`` after ``CROUCH_DELAY``.
2. **Lean loop** (:class:`LeanSteering`). The baseline's :class:`~ridempc.baselines.
   cassie_segway.ShiftLoop` on the yaw rate :math:`\\hat\\omega` [rad/s] (the estimate's
   base angular velocity about world z) gives a lean :math:`s` [m] (``LEAN_GAINS``, the
   ``pd`` rider's ``[turning]`` gains: feedforward on the command, PI on the error, bounded
   and slewed), and the MPC's centre-of-mass reference moves sideways by

   .. math:: y^{CoM}_k \\mathrel{+}= g\\, s

   [m] in the library frame (y to the left), with the static balance shift of the forces
   (:func:`~ridempc.mpc.statics.static_shift`: load moves onto the near foot).
   :math:`g` = ``LEAN_PULL``: the pad pushes back on the shins with a force that neither the
   MPC nor the whole-body QP models, and each MPC tick plans from where that force has
   left the rider, so the centre of mass settles at a fraction of its reference's offset.
   Measured on the Segway's circle (2 m/s at 0.5 rad/s, seed 0) with a prototype that
   lowered the reference by the ``pd`` rider's pelvis drop, 0.277 m: at :math:`g = 1` the
   lean saturated at 0.1 m while the pelvis moved 0.012 m off the platform's centre, the
   bar tilted 0.01 rad and the Segway turned at 0.07 rad/s (yaw-rate RMSE 0.429 rad/s); at
   2.5, 4, 6 and 8 the RMSE was 0.304, 0.195, 0.087 and 0.057 rad/s (the ``pd`` baseline's
   0.043), the bar at about 0.06 rad. As built (the keyframes' 0.255 m, :math:`g = 8`):
   0.063 rad/s.

   The rider follows a commanded turn only while the board rolls at ``HEADING_SPEED`` or
   more, where the library frame turns with the board's direction of travel
   (:meth:`~ridempc.mpc.state_map.StateMap.follow_sideways`); slower, the loop holds the
   yaw rate at zero. Standing still the frame keeps its heading, the plan holds the rider's
   yaw against the turning platform, the loop winds up, and the bar was pushed to 0.26
   rad: the Segway spun at 1.5 rad/s and Cassie fell 2 s after a 0.5 rad/s command
   (turning in place is left undone). Without the loop at all below that speed, the
   offset-start's crouched rider pushed the bar unchecked and fell.
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.baselines.cassie_segway import ShiftLoop
from ridempc.baselines.cassie_segway_gains import LoopGains
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.state_map import HEADING_SPEED
from ridempc.mpc.statics import StaticShift
from ridempc.robots.robot import Robot

__all__ = [
    "CROUCH_DELAY",
    "CROUCH_SECONDS",
    "LEAN_GAINS",
    "LEAN_PULL",
    "Crouch",
    "LeanSteering",
    "com_height",
]

Array = NDArray[np.float64]
CROUCH_DELAY: float = 0.5  # [s] after the ride starts
CROUCH_SECONDS: float = 2.0  # [s] to bring the lowered height in
LEAN_GAINS = LoopGains(
    feedforward=0.08,  # [m per rad/s]
    feedforward_rate=0.0,
    kp=0.03,  # [m per rad/s]
    ki=0.1,  # [m per rad]
    integral_limit=0.08,  # [m]
    max_shift=0.1,  # [m]
    max_rate=0.1,  # [m/s]
    filter_hz=5.0,  # [Hz] on the yaw rate
)
LEAN_PULL: float = 8.0  # [-] the reference's offset per metre of lean (module docstring)


def com_height(robot: Robot, qpos: Array) -> float:
    """Height of the robot's centre of mass over the mean of its contact sites [m] at the
    MuJoCo configuration ``qpos``."""
    model = robot.mj_model
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    sites = [model.site(name).id for name in robot.params.contact_sites]
    return float(data.subtree_com[0][2] - np.mean(data.site_xpos[sites, 2]))


class Crouch:
    """The MPC's centre-of-mass height reference lowered by ``drop`` [m] (negative: down),
    brought in linearly over ``CROUCH_SECONDS`` after ``CROUCH_DELAY`` (module docstring).

    Args:
        drop: :math:`\\Delta z` [m].
    """

    def __init__(self, drop: float) -> None:
        if not math.isfinite(drop):
            raise ValueError(f"crouch: height change {drop} m")
        self.drop = drop
        self._start: float | None = None

    @classmethod
    def of(cls, robot: Robot, board: str) -> Crouch | None:
        """The crouch from the robot's stance on ``board`` to its riding keyframe, or None
        when it rides in its stance."""
        if board not in robot.params.ride_keyframes:
            return None
        drop = com_height(robot, robot.ride_qpos(board)) - com_height(
            robot, robot.stance_qpos(board)
        )
        return cls(drop)

    def lower(self, problem: MpcProblem, index: int, now: float) -> MpcProblem:
        """``problem`` with its reference's state ``index`` (the CoM height) lowered by the
        share of the drop brought in at ``now`` [s]."""
        if self._start is None:
            self._start = now
        share = min(max((now - self._start - CROUCH_DELAY) / CROUCH_SECONDS, 0.0), 1.0)
        if share == 0.0:
            return problem
        states = problem.state_reference.copy()
        states[:, index] += self.drop * share
        return replace(problem, state_reference=states)


class LeanSteering:
    """The lean loop (module docstring): the yaw rate to a sideways offset of the MPC's
    centre-of-mass reference.

    Args:
        gains: The loop's gains (its shift is the lean :math:`s` [m]).
        pull: :math:`g`, the reference's offset per metre of lean [-].
    """

    def __init__(
        self,
        gains: LoopGains = LEAN_GAINS,
        pull: float = LEAN_PULL,
        min_speed: float = HEADING_SPEED,
    ) -> None:
        if not pull > 0.0:
            raise ValueError(f"lean steering: pull {pull} must be positive")
        self.loop = ShiftLoop(gains)
        self.pull = pull
        self.min_speed = min_speed
        self.offset = 0.0  # [m] the last offset laid over the reference

    def update(self, now: float, command: float, yaw_rate: float, speed: float) -> float:
        """The reference's offset [m] for the commanded and the estimated yaw rate
        [rad/s] at ``now`` [s] and the board's forward ``speed`` [m/s]; below ``min_speed``
        the loop holds the yaw rate at zero, whatever the command."""
        wanted = command if abs(speed) >= self.min_speed else 0.0
        self.offset = self.pull * self.loop(now, wanted, yaw_rate)
        return self.offset

    def lean(self, problem: MpcProblem, index: int, balance: StaticShift | None) -> MpcProblem:
        """``problem`` with its reference's state ``index`` (the CoM's y) moved by the
        offset, and with ``balance`` (the reference's change per metre of it) moved along."""
        if self.offset == 0.0:
            return problem
        states = problem.state_reference.copy()
        inputs = problem.input_reference.copy()
        if balance is not None:
            states += self.offset * balance.states[None, :]
            inputs += self.offset * balance.inputs[None, :]
        states[:, index] = problem.state_reference[:, index] + self.offset
        return replace(problem, state_reference=states, input_reference=inputs)
