"""Scripted experiments on the Segway carrying a dead weight, for identification and tests.

The rider's two inputs are played by external torques (``Simulation(external=...)``), as a
rider's body would apply them, each with its reaction on the dead weight where the rider's
own body would take it:

- the pitch torque :math:`u_\\theta` [N m] on the dead weight about the platform's lateral
  axis (positive: leaning forward, nose down), passed to the platform through the contact;
- the knee torque :math:`\\tau_k` [N m] on the knee bar about its hinge axis (positive:
  pushing the bar to the left), with the opposite torque on the dead weight.

The board's state is recorded at the firmware rate from the simulator's true state (the
judge's view; the firmware never sees it).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.errors import RidempcError
from ridempc.rotations import pitch_of, yaw_of
from ridempc.scenarios.scenario import Scenario
from ridempc.sim.scene import BOARD_PREFIX, build_scene
from ridempc.sim.simulation import Simulation

__all__ = [
    "PHYSICS_HZ",
    "Signal",
    "Trial",
    "piecewise",
    "random_steps",
    "run_trial",
    "sine",
]

PHYSICS_HZ: int = 1500
RECORD_HZ: int = 500  # [Hz] the firmware rate of the miniPro-class board
Signal = Callable[[float], float]


def piecewise(edges: Sequence[float], levels: Sequence[float]) -> Signal:
    """Piecewise-constant signal: ``levels[i]`` from ``edges[i]`` on, zero before the first."""
    times, values = np.asarray(edges, dtype=float), np.asarray(levels, dtype=float)

    def signal(t: float) -> float:
        i = int(np.searchsorted(times, t, side="right")) - 1
        return float(values[i]) if i >= 0 else 0.0

    return signal


def random_steps(
    seed: int, duration: float, amplitude: float, hold: tuple[float, float], start: float = 0.5
) -> Signal:
    """Piecewise-constant signal, levels uniform in +-amplitude, each held ``hold`` [s]."""
    rng = np.random.default_rng(seed)
    times, levels, t = [], [], start
    while t < duration:
        times.append(t)
        levels.append(rng.uniform(-amplitude, amplitude))
        t += rng.uniform(*hold)
    return piecewise(times, levels)


def sine(amplitude: float, frequency: float, start: float = 0.5) -> Signal:
    """:math:`a \\sin(2 \\pi f (t - t_0))` after ``start``, zero before."""

    def signal(t: float) -> float:
        return amplitude * np.sin(2 * np.pi * frequency * (t - start)) if t >= start else 0.0

    return signal


@dataclass(frozen=True)
class Trial:
    """One recorded experiment, sampled at ``RECORD_HZ``.

    Attributes:
        time: [s]
        u_theta: Rider pitch torque on the platform [N m].
        knee_torque: Torque pushing the knee bar to the left [N m].
        knee_bar: Knee-bar angle, positive pushed to the left [rad].
        theta: Platform pitch, positive nose down [rad].
        theta_rate: Platform pitch rate [rad/s].
        speed: Forward speed of the axle's middle [m/s].
        yaw_rate: Yaw rate, positive to the left [rad/s].
        x: Axle middle, world x [m].
        y: Axle middle, world y [m].
        psi: Heading [rad] (unwrapped).
        fell: Whether the board or the weight fell.
    """

    time: NDArray[np.float64]
    u_theta: NDArray[np.float64]
    knee_torque: NDArray[np.float64]
    knee_bar: NDArray[np.float64]
    theta: NDArray[np.float64]
    theta_rate: NDArray[np.float64]
    speed: NDArray[np.float64]
    yaw_rate: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    psi: NDArray[np.float64]
    fell: bool

    @property
    def dt(self) -> float:
        return float(self.time[1] - self.time[0])


def run_trial(
    board: Board,
    dead_weight: float,
    duration: float,
    u_theta: Signal,
    knee_torque: Signal,
) -> Trial:
    """Ride the board with a dead weight under scripted rider torques and record it.

    Args:
        board: A Segway.
        dead_weight: Mass of the dead weight [kg].
        duration: [s]
        u_theta: Pitch torque on the platform through the weight [N m], by time.
        knee_torque: Torque pushing the knee bar to the left [N m], by time.
    """
    scene = build_scene(None, PHYSICS_HZ, board=board, dead_weight=dead_weight)
    model = scene.model
    chassis = scene.body_id(BOARD_PREFIX + "chassis")
    bar = scene.body_id(BOARD_PREFIX + "knee_bar")
    weight = scene.base_body
    hinge = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, BOARD_PREFIX + "knee_bar_hinge")
    if min(chassis, bar, hinge) < 0:
        raise RidempcError(f"board '{board.name}' is not a Segway (no chassis or knee bar)")
    knee_adr = int(model.jnt_qposadr[hinge])
    free_dof = int(model.jnt_dofadr[model.body_jntadr[chassis]])
    every = PHYSICS_HZ // RECORD_HZ
    rows: list[list[float]] = []
    tick = [0]
    velocity = np.empty(6)

    def external(t: float, m: mujoco.MjModel, data: mujoco.MjData) -> None:
        axes = data.xmat[chassis].reshape(3, 3)  # columns: forward, left, up
        u, k = u_theta(t), knee_torque(t)
        data.xfrc_applied[weight, 3:] += u * axes[:, 1] + k * axes[:, 0]
        data.xfrc_applied[bar, 3:] -= k * axes[:, 0]
        if tick[0] % every == 0:
            mujoco.mj_objectVelocity(m, data, mujoco.mjtObj.mjOBJ_BODY, chassis, velocity, 1)
            pitch, yaw = pitch_of(data.xquat[chassis]), yaw_of(data.xquat[chassis])
            linear = data.qvel[free_dof : free_dof + 3]
            rows.append(
                [
                    t,
                    u,
                    k,
                    float(data.qpos[knee_adr]),
                    pitch,
                    float(velocity[1]),
                    float(np.cos(yaw) * linear[0] + np.sin(yaw) * linear[1]),
                    float((axes @ velocity[:3])[2]),
                    float(data.xpos[chassis, 0]),
                    float(data.xpos[chassis, 1]),
                    yaw,
                ]
            )
        tick[0] += 1

    result = Simulation(
        scene, None, Scenario(name="segway-experiment", duration=duration), external=external
    ).run()
    if result.status == "failed":
        raise RidempcError(f"Segway experiment diverged: {result.error}")
    a = np.array(rows)
    return Trial(
        time=a[:, 0],
        u_theta=a[:, 1],
        knee_torque=a[:, 2],
        knee_bar=a[:, 3],
        theta=a[:, 4],
        theta_rate=a[:, 5],
        speed=a[:, 6],
        yaw_rate=a[:, 7],
        x=a[:, 8],
        y=a[:, 9],
        psi=np.unwrap(a[:, 10]),
        fell=result.fell,
    )
