"""Turning a Segway by leaning into its knee bar: the MPC rider's crouch and lean loop.

The Segway's firmware turns at :math:`\\dot\\psi_{ref} = k_{turn} \\delta`, with
:math:`\\delta` [rad] the tilt of the knee bar that the rider's shins push (Segway paper,
IV-B: "To turn, Cassie needs to lean into the center bar with her legs, which is
accomplished by shifting :math:`p_y^{CoM}`"). The bar is not in the MPC's model as a push of
the legs: a plan that moved the library's ``knee_bar`` input would count on a push nobody
gives, so the rider holds that input at zero and leans instead, as the ``pd`` baseline
(:mod:`ridempc.baselines.cassie_segway`) does:

1. **Crouch** (:class:`Crouch`). Standing tall, Cassie's shins pass 0.13-0.24 m behind the
   pad. The rider rides in the pair's riding keyframe (``ride_keyframe``): its whole-body
   posture task holds that keyframe's motor angles, and the MPC's centre-of-mass height
   reference is lowered by

   .. math:: \\Delta z = h_{ride} - h_{stance}

   [m], the difference of the two keyframes' centre-of-mass heights over the mean of their
   contact sites (the library was built standing: -0.255 m for Cassie), brought in linearly
   over ``CROUCH_SECONDS`` after ``CROUCH_DELAY``.
2. **Lean loop** (:class:`LeanSteering`). The baseline's :class:`~ridempc.baselines.
   cassie_segway.ShiftLoop` on the yaw rate :math:`\\hat\\omega` [rad/s] (the estimate's
   base angular velocity about world z) gives a lean :math:`s` [m] (``LEAN_GAINS``, the
   ``pd`` rider's ``[turning]`` gains but slewed twice as fast: feedforward on the command,
   PI on the error, bounded), and the MPC's centre-of-mass reference moves sideways in the
   library frame (y to the left), with the static balance shift of the forces
   (:func:`~ridempc.mpc.statics.static_shift`: load moves onto the near foot).

   *Riding* (the board at ``HEADING_SPEED`` or more, where the library frame turns with
   the board's direction of travel, :meth:`~ridempc.mpc.state_map.StateMap.
   follow_sideways`), the reference is the lean itself, reached along a path from where
   the centre of mass is, :math:`y_0` [m] (off the reference's line),

   .. math:: y_k = s + (y_0 - s)\\, e^{-k \\Delta t / T}, \\qquad
       \\dot y_k = -\\frac{y_0 - s}{T}\\, e^{-k \\Delta t / T}

   over the horizon's nodes :math:`k`, :math:`T` = ``LEAN_SECONDS``; and the MPC is told of
   the turn the lean makes (:meth:`LeanSteering.turn`, :meth:`LeanSteering.drift`):

   - the rider's and the board's headings and yaw rates in the reference turn at the
     commanded rate :math:`\\omega^*`, :math:`\\psi_k \\mathrel{+}= \\omega^* k \\Delta t`,
     :math:`\\omega_{z,k} \\mathrel{+}= \\omega^*`: held at zero yaw rate, the plan would
     brake the rider's yaw while the board turns under her (the measured yaw rate, laid
     on instead, feeds itself);
   - the heading the library frame follows (the board's direction of travel, low-passed
     over 0.3 s) is carried by the same commanded rate
     (:meth:`~ridempc.mpc.state_map.StateMap.follow_sideways`): low-passed alone, it
     lags a steady turn, and the MPC would hold the pelvis outside it;
   - the frame that follows the board turns with it at :math:`\\hat\\omega`, which the
     MPC's model does not know: in it the centre of mass feels the centrifugal
     acceleration :math:`-v \\hat\\omega` across the heading (:math:`v` the board's
     speed [m/s]), added to the rates of :math:`\\dot y` as a drift (0.5 m/s² at 1 m/s and
     0.5 rad/s, which the rider meets by leaning into the turn).

   Each of the four (the path, the turned yaw references, the turn carried by the
   followed heading, the centrifugal drift) takes its share of the yaw-rate error off
   (``docs/tuning.md``); the board's steering still waits the 0.3 s the lean takes to
   push the bar.

   *Standing* (slower), the loop holds the yaw rate at zero, whatever the command, and the
   reference sits at ``STANDING_PULL`` :math:`\\times s` over the whole horizon:
   the pad pushes back on the shins with a force that neither the MPC nor the whole-body
   QP models, and each MPC tick plans from where that force has left the rider, so the
   centre of mass settles at a fraction of its reference's offset, which
   ``STANDING_PULL`` makes up for (found on the circle). Standing still the frame keeps its
   heading and the plan would hold the rider's yaw against a turning platform, so the loop
   does not turn in place (left undone); without the loop at all a crouched rider's shin
   pushes the bar unchecked.
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.baselines.cassie_segway import ShiftLoop
from ridempc.baselines.cassie_segway_gains import LoopGains
from ridempc.mpc.manoeuvre import StateLayout, turn_headings
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.riding_posture import ride_keyframe, ride_qpos
from ridempc.mpc.state_map import HEADING_SPEED
from ridempc.mpc.statics import StaticShift
from ridempc.robots.robot import Robot

__all__ = [
    "CROUCH_DELAY",
    "CROUCH_SECONDS",
    "LEAN_GAINS",
    "LEAN_SECONDS",
    "STANDING_PULL",
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
    # [m/s] twice the pd rider's: riding, the path takes the centre of mass there
    max_rate=0.2,
    filter_hz=5.0,  # [Hz] on the yaw rate
)
LEAN_SECONDS: float = 0.2  # [s] T, the riding lean's path (module docstring)
STANDING_PULL: float = 8.0  # [-] standing, the reference's offset per metre of lean


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
        if ride_keyframe(robot, board) is None:
            return None
        drop = com_height(robot, ride_qpos(robot, board)) - com_height(
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
    centre-of-mass reference, and, riding, the turn it makes told to the MPC.

    Args:
        gains: The loop's gains (its shift is the lean :math:`s` [m]).
        standing_pull: Standing, the reference's offset per metre of lean [-].
        min_speed: The board's least speed for riding [m/s].
        seconds: :math:`T`, the riding lean's path [s].

    Attributes:
        offset: The last offset laid over the reference [m]: :math:`s` riding, ``standing_pull``
            :math:`\\times s` standing.
        riding: Whether the last update found the board at ``min_speed`` or more.
        turn_rate: :math:`\\omega^*`, the yaw rate the last update followed [rad/s] (zero
            standing).
    """

    def __init__(
        self,
        gains: LoopGains = LEAN_GAINS,
        standing_pull: float = STANDING_PULL,
        min_speed: float = HEADING_SPEED,
        seconds: float = LEAN_SECONDS,
    ) -> None:
        if not standing_pull > 0.0:
            raise ValueError(f"lean steering: standing pull {standing_pull} must be positive")
        if not seconds > 0.0:
            raise ValueError(f"lean steering: path time constant {seconds} s must be positive")
        self.loop = ShiftLoop(gains)
        self.standing_pull = standing_pull
        self.min_speed = min_speed
        self.seconds = seconds
        self.offset = 0.0
        self.riding = False
        self.turn_rate = 0.0

    def update(self, now: float, command: float, yaw_rate: float, speed: float) -> float:
        """The reference's offset [m] for the commanded and the estimated yaw rate
        [rad/s] at ``now`` [s] and the board's forward ``speed`` [m/s]; below ``min_speed``
        the loop holds the yaw rate at zero, whatever the command."""
        self.riding = abs(speed) >= self.min_speed
        self.turn_rate = command if self.riding else 0.0
        shift = self.loop(now, self.turn_rate, yaw_rate)
        self.offset = shift if self.riding else self.standing_pull * shift
        return self.offset

    def lean(
        self, problem: MpcProblem, index: int, rate: int, balance: StaticShift | None
    ) -> MpcProblem:
        """``problem`` with its reference's state ``index`` (the CoM's y) moved by the
        offset, and with ``balance`` (the reference's change per metre of it) moved along:
        riding, along the path from the initial state's offset to it, with the path's rate
        on state ``rate`` (the CoM's :math:`\\dot y`); standing, by the offset at every node.
        A zero offset leaves the problem as it is."""
        if self.offset == 0.0:
            return problem
        states = problem.state_reference.copy()
        inputs = problem.input_reference.copy()
        nodes = states.shape[0]
        if self.riding:
            start = problem.initial_state[index] - problem.state_reference[0, index]
            decay = np.exp(-np.arange(nodes) * problem.dt / self.seconds)
            path = self.offset + (start - self.offset) * decay
            states[:, rate] -= (start - self.offset) / self.seconds * decay
        else:
            path = np.full(nodes, self.offset)
        if balance is not None:
            states += path[:, None] * balance.states[None, :]
            inputs += path[: inputs.shape[0], None] * balance.inputs[None, :]
        states[:, index] = problem.state_reference[:, index] + path
        return replace(problem, state_reference=states, input_reference=inputs)

    def turn(self, problem: MpcProblem, layout: StateLayout) -> MpcProblem:
        """Riding, ``problem`` with its reference's headings turned at the followed yaw
        rate from the first node, :math:`\\psi_k \\mathrel{+}= \\omega^* k \\Delta t`, and
        its yaw rates (the base's :math:`\\omega_z`, the board's) raised by it
        (:func:`~ridempc.mpc.manoeuvre.turn_headings`); as it is standing or not turning."""
        if not self.riding or self.turn_rate == 0.0:
            return problem
        states = problem.state_reference.copy()
        nodes = states.shape[0]
        turned = np.asarray(self.turn_rate * problem.dt * np.arange(nodes), dtype=np.float64)
        turn_headings(states, layout, turned, np.full(nodes, self.turn_rate))
        return replace(problem, state_reference=states)

    def drift(self, nx: int, rate: int, speed: float, yaw_rate: float) -> Array | None:
        """Riding, the centrifugal acceleration of the frame that turns with the board as
        a drift of the MPC's rates (nx), :math:`-v \\hat\\omega` [m/s²] on state ``rate``
        (the CoM's :math:`\\dot y`) for the board's ``speed`` :math:`v` [m/s] and the
        estimated ``yaw_rate`` :math:`\\hat\\omega` [rad/s]; None standing."""
        if not self.riding:
            return None
        drift = np.zeros(nx)
        drift[rate] = -speed * yaw_rate
        return drift
