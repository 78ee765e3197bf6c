"""Scripted experiments on the simulated skateboard carrying a dead weight.

The experimenter's hands are forces added through the simulation's ``external`` hook (the
board's own no-op firmware runs as usual):

- a **roll torque** about the deck's forward axis, either scripted in time (roll trials)
  or a PD hold of a roll reference (steering trials);
- in steering trials, a **push** along the deck's heading on the deck and on the dead
  weight, in proportion to their masses (so the weight does not slide), holding a speed.

Every physics step records the deck's roll :math:`\\varphi` (ZYX roll of the deck) [rad],
roll rate :math:`\\psi` (deck-frame angular velocity about its x axis) [rad/s], the scripted
torque and the **rider's roll torque** on the deck, :math:`\\tau = -(R_B^\\top \\sum_i
r_{B_i} \\times f_i)_x` of eq. (7), moments about the platform site (the deck's top centre)
of the contact wrench the dead weight puts on the deck, plus heading, yaw rate, forward
speed and the position of :math:`C_B` for the kinematics of eqs. (11)-(14).

Inside the hook MuJoCo's derived quantities (poses, velocities, contact wrenches
``cfrc_ext``) belong to the state *before* the step just taken, together with the torque
applied in that step, so each row pairs them consistently.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.boards.identification import IdentificationFailed
from ridempc.boards.skateboard.model import DECK, PLATFORM_SITE
from ridempc.boards.skateboard.parameters import SkateboardParameters
from ridempc.boards.skateboard.reduced import steering_axle_distances
from ridempc.rotations import roll_of, yaw_of
from ridempc.scenarios.scenario import Scenario
from ridempc.sim.scene import BOARD_PREFIX, Scene, build_scene
from ridempc.sim.simulation import Simulation

__all__ = [
    "RollHold",
    "SteeringTrial",
    "TrialRecord",
    "chirp",
    "multisine",
    "run_roll_trial",
    "run_steering_trial",
    "skateboard_scene",
    "steps",
]

Array = NDArray[np.float64]
Signal = Callable[[float], float]
PHYSICS_HZ = 1500
HOLD_STIFFNESS = 300.0  # [N m / rad] the experimenter's grip on the deck's roll
HOLD_DAMPING = 6.0  # [N m s / rad]
HOLD_FEEDFORWARD = 45.0  # [N m / rad] about the loaded deck's roll stiffness
PUSH_GAIN = 8.0  # [1 / s] speed error to commanded acceleration
PUSH_MAX_ACCELERATION = 2.5  # [m / s^2] gentle enough for the weight to stay put


def multisine(amplitude: float, frequencies: tuple[float, ...], seed: int) -> Signal:
    """Sum of sines with random phases, RMS ``amplitude / sqrt(2)`` [N m]; frequencies [Hz]."""
    phases = np.random.default_rng(seed).uniform(0.0, 2.0 * math.pi, len(frequencies))
    scale = amplitude / math.sqrt(len(frequencies))

    def signal(t: float) -> float:
        return scale * sum(
            math.sin(2.0 * math.pi * f * t + p) for f, p in zip(frequencies, phases, strict=True)
        )

    return signal


def chirp(amplitude: float, f0: float, f1: float, duration: float) -> Signal:
    """Linear chirp from ``f0`` to ``f1`` [Hz] over ``duration`` [s]."""
    rate = (f1 - f0) / duration

    def signal(t: float) -> float:
        return amplitude * math.sin(2.0 * math.pi * (f0 * t + 0.5 * rate * t * t))

    return signal


def steps(levels: tuple[float, ...], dwell: float) -> Signal:
    """Piecewise-constant levels, each held ``dwell`` [s] (the last one thereafter)."""

    def signal(t: float) -> float:
        return levels[min(int(t / dwell), len(levels) - 1)]

    return signal


@dataclass(frozen=True)
class RollHold:
    """A roll reference the experimenter holds the deck at [rad]: zero before ``start``, then
    ``bias + amplitude sin(2 pi (t - start) / period)``.

    Attributes:
        start: When the roll reference starts [s].
        bias: Constant roll [rad].
        amplitude: Sine amplitude [rad].
        period: Sine period [s].
    """

    start: float
    bias: float
    amplitude: float = 0.0
    period: float = 3.0

    def __call__(self, t: float) -> float:
        if t < self.start:
            return 0.0
        return self.bias + self.amplitude * math.sin(2.0 * math.pi * (t - self.start) / self.period)


@dataclass(frozen=True)
class SteeringTrial:
    """Push the loaded board to ``speed`` [m/s] and hold its roll at ``roll(t)`` [rad]."""

    name: str
    speed: float
    roll: RollHold
    duration: float


@dataclass(frozen=True)
class TrialRecord:
    """One experiment's time series, one row per physics step.

    Attributes:
        name: Trial name.
        time: [s].
        roll: Deck roll :math:`\\varphi` [rad].
        roll_rate: Deck roll rate :math:`\\psi` [rad/s].
        torque_external: Scripted roll torque about the deck's x axis [N m].
        torque_rider: Rider's roll torque on the deck about the platform site [N m].
        heading: Deck yaw [rad].
        yaw_rate: World-vertical angular velocity of the deck [rad/s].
        speed: Forward speed of :math:`C_B` along the heading [m/s].
        position: Horizontal position of :math:`C_B` [m], shape (n, 2).
    """

    name: str
    time: Array
    roll: Array
    roll_rate: Array
    torque_external: Array
    torque_rider: Array
    heading: Array
    yaw_rate: Array
    speed: Array
    position: Array

    def window(self, start: float) -> TrialRecord:
        """The rows from ``start`` [s] on."""
        keep = self.time >= start - 1e-9
        return TrialRecord(
            name=self.name,
            **{
                key: getattr(self, key)[keep]
                for key in (
                    "time",
                    "roll",
                    "roll_rate",
                    "torque_external",
                    "torque_rider",
                    "heading",
                    "yaw_rate",
                    "speed",
                    "position",
                )
            },
        )


def skateboard_scene(board: Board, dead_weight: float) -> Scene:
    """The board at rest with a dead weight of ``dead_weight`` [kg] on its platform."""
    return build_scene(None, PHYSICS_HZ, board=board, dead_weight=dead_weight)


class _Experimenter:
    """The ``external`` hook: applies the scripted forces and records a row each step."""

    def __init__(
        self,
        scene: Scene,
        torque: Signal | None = None,
        hold: RollHold | None = None,
        speed: float = 0.0,
    ) -> None:
        model = scene.model
        params = scene.board.params if scene.board is not None else None
        assert isinstance(params, SkateboardParameters)
        self._deck = scene.body_id(BOARD_PREFIX + DECK)
        self._weight = scene.base_body
        self._site = mujoco.mj_name2id(
            model, mujoco.mjtObj.mjOBJ_SITE, BOARD_PREFIX + PLATFORM_SITE
        )
        board_bodies = sorted(scene.board_bodies)
        self._board_mass = float(model.body_mass[board_bodies].sum())
        self._weight_mass = float(model.body_mass[self._weight])
        l_front, _ = steering_axle_distances(
            math.radians(params.rake_front), math.radians(params.rake_rear), params.wheelbase
        )
        self._c_b = 0.5 * params.wheelbase - l_front  # C_B ahead of the deck centre [m]
        self._torque = torque
        self._hold = hold
        self._speed = speed
        self._applied = 0.0
        self._velocity = np.empty(6)
        self.rows: list[tuple[float, ...]] = []

    def __call__(self, t: float, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        deck, weight = self._deck, self._weight
        rotation = data.xmat[deck].reshape(3, 3)
        roll, heading = roll_of(data.xquat[deck]), yaw_of(data.xquat[deck])
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_XBODY, deck, self._velocity, 0)
        omega_world, velocity = self._velocity[:3], self._velocity[3:]
        roll_rate = float(rotation[:, 0] @ omega_world)
        forward = np.array([math.cos(heading), math.sin(heading), 0.0])
        speed = float(forward @ velocity)
        # The contact wrench on the weight about its CoM (cfrc_ext, recomputed now that the
        # loop has cleared xfrc_applied, so it holds contact forces only).
        mujoco.mj_rnePostConstraint(model, data)
        wrench = data.cfrc_ext[weight]
        lever = data.subtree_com[weight] - data.site_xpos[self._site]
        moment = wrench[:3] + np.cross(lever, wrench[3:])
        rider = -float(rotation[:, 0] @ moment)
        centre = data.xpos[deck, :2] + self._c_b * rotation[:2, 0]
        if t > 0.0:  # derived quantities are those of the previous step's state
            self.rows.append(
                (
                    t - 1.0 / PHYSICS_HZ,
                    roll,
                    roll_rate,
                    self._applied,
                    rider,
                    heading,
                    float(omega_world[2]),
                    speed,
                    centre[0],
                    centre[1],
                )
            )
        torque = self._torque(t) if self._torque is not None else 0.0
        if self._hold is not None:
            target = self._hold(t)
            torque += (
                HOLD_FEEDFORWARD * target
                + HOLD_STIFFNESS * (target - roll)
                - HOLD_DAMPING * roll_rate
            )
        data.xfrc_applied[deck, 3:] += rotation[:, 0] * torque
        self._applied = torque
        if self._speed > 0.0:
            accel = float(
                np.clip(
                    PUSH_GAIN * (self._speed - speed), -PUSH_MAX_ACCELERATION, PUSH_MAX_ACCELERATION
                )
            )
            data.xfrc_applied[deck, :3] += forward * accel * self._board_mass
            data.xfrc_applied[weight, :3] += forward * accel * self._weight_mass

    def record(self, name: str) -> TrialRecord:
        rows = np.array(self.rows)
        return TrialRecord(
            name=name,
            time=rows[:, 0],
            roll=rows[:, 1],
            roll_rate=rows[:, 2],
            torque_external=rows[:, 3],
            torque_rider=rows[:, 4],
            heading=np.unwrap(rows[:, 5]),
            yaw_rate=rows[:, 6],
            speed=rows[:, 7],
            position=rows[:, 8:10],
        )


def _run(scene: Scene, experimenter: _Experimenter, name: str, duration: float) -> TrialRecord:
    simulation = Simulation(
        scene, None, Scenario(name=name, duration=duration), log_hz=10.0, external=experimenter
    )
    result = simulation.run()
    if result.status != "ok":
        raise IdentificationFailed(
            f"trial '{name}' did not finish: {result.status} "
            f"({result.fall_reason or result.error}) at t = {result.sim_time:.2f} s"
        )
    return experimenter.record(name)


def run_roll_trial(scene: Scene, name: str, torque: Signal, duration: float) -> TrialRecord:
    """Standing board, a scripted roll torque [N m] on the deck for ``duration`` [s]."""
    return _run(scene, _Experimenter(scene, torque=torque), name, duration)


def run_steering_trial(scene: Scene, trial: SteeringTrial) -> TrialRecord:
    """Board pushed to ``trial.speed`` with its roll held at ``trial.roll(t)``."""
    experimenter = _Experimenter(scene, hold=trial.roll, speed=trial.speed)
    return _run(scene, experimenter, trial.name, trial.duration)
