"""A robot: its MJCF description, its parameter file, and what follows from them.

The description is compiled once on its own (no floor, no board) to read what both
the simulation and the controllers need: motor joints, gear ratios, peak torques and
the standing keyframe. Everything here is read from the two files in
``robots/<name>/``; nothing is specific to one robot.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.checks import readable_file
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.paths import robots_dir
from ridempc.robots.parameters import RobotParameters, load_robot_parameters

__all__ = ["Motor", "Robot", "load_robot", "robot_names"]


@dataclass(frozen=True)
class Motor:
    """One actuated joint.

    Attributes:
        name: Actuator name, equal to its joint's name.
        joint: Joint name.
        gear: Gear ratio (joint torque = gear * motor torque).
        torque_limit: Joint-side peak torque [N m] (= gear * motor-side limit).
        speed_limit: Joint no-load speed [rad / s]: no torque at or beyond it.
        kp: Default low-level stiffness [N m / rad].
        kd: Default low-level damping [N m s / rad].
        full_torque_fraction: Share of ``speed_limit`` up to which the peak torque is
            available [-] (:class:`~ridempc.robots.motor_curve.TorqueSpeedCurve`).
        torque_delay: Time a torque command takes to reach the joint [s].
    """

    name: str
    joint: str
    gear: float
    torque_limit: float
    speed_limit: float
    kp: float
    kd: float
    full_torque_fraction: float
    torque_delay: float


@dataclass(frozen=True)
class Robot:
    """A robot read from ``robots/<name>/`` (see ``robots/README.md``)."""

    params: RobotParameters
    folder: Path
    _cache: dict[str, object] = field(default_factory=dict, compare=False, repr=False)

    @property
    def name(self) -> str:
        return self.params.name

    @property
    def mjcf_path(self) -> Path:
        return self.folder / self.params.description

    def spec(self) -> mujoco.MjSpec:
        """A fresh, editable MuJoCo spec of the description."""
        try:
            return mujoco.MjSpec.from_file(str(self.mjcf_path))
        except ValueError as exc:
            raise ConfigError(f"{self.mjcf_path}: MuJoCo cannot read it ({exc})") from exc

    @cached_property
    def mj_model(self) -> mujoco.MjModel:
        """The description compiled alone (no floor), for reading its figures."""
        try:
            return self.spec().compile()
        except ValueError as exc:
            raise ConfigError(f"{self.mjcf_path}: MuJoCo cannot compile it ({exc})") from exc

    @cached_property
    def motors(self) -> tuple[Motor, ...]:
        """Motors in actuator order, checked against ``robot.toml``."""
        model = self.mj_model
        motors = []
        names = set()
        for i in range(model.nu):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, i)
            joint_id = int(model.actuator_trnid[i, 0])
            joint = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint_id)
            if name not in self.params.motors:
                raise ConfigError(
                    f"{self.folder / 'robot.toml'}: field 'motors.{name}': missing "
                    f"(the description has actuator '{name}')"
                )
            gear = float(model.actuator_gear[i, 0])
            ctrl_max = float(np.max(np.abs(model.actuator_ctrlrange[i])))
            p = self.params.motors[name]
            motors.append(
                Motor(
                    name,
                    joint,
                    gear,
                    gear * ctrl_max,
                    p.speed_limit,
                    p.kp,
                    p.kd,
                    p.full_torque_fraction,
                    p.torque_delay,
                )
            )
            names.add(name)
        extra = set(self.params.motors) - names
        if extra:
            raise ConfigError(
                f"{self.folder / 'robot.toml'}: field 'motors.{sorted(extra)[0]}': "
                f"no such actuator in {self.params.description}"
            )
        return tuple(motors)

    @cached_property
    def stand_qpos(self) -> NDArray[np.float64]:
        """Standing configuration from the description's keyframe [MuJoCo qpos]."""
        return self.keyframe_qpos(self.params.stand_keyframe)

    def stance_qpos(self, board: str) -> NDArray[np.float64]:
        """The configuration to start from on ``board`` (the stand unless a stance is given)."""
        return self.keyframe_qpos(
            self.params.stance_keyframes.get(board, self.params.stand_keyframe)
        )

    def keyframe_qpos(self, name: str) -> NDArray[np.float64]:
        """A keyframe of the description [MuJoCo qpos]."""
        model = self.mj_model
        key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, name)
        if key < 0:
            raise ConfigError(f"{self.mjcf_path}: keyframe '{name}' not found")
        return np.array(model.key_qpos[key], dtype=float)

    @cached_property
    def mass(self) -> float:
        """Total mass [kg]."""
        return float(np.sum(self.mj_model.body_mass))

    @property
    def encoder_joints(self) -> tuple[str, ...]:
        """Joints with encoders: the motor joints, then the instrumented passive joints."""
        return tuple(m.joint for m in self.motors) + self.params.encoder_joints


def robot_names() -> tuple[str, ...]:
    """Names of the robots that exist (folders of ``robots/`` holding a ``robot.toml``)."""
    root = robots_dir()
    return tuple(sorted(p.parent.name for p in root.glob("*/robot.toml")))


def load_robot(name: str) -> Robot:
    """Load a robot by name.

    Raises:
        UnknownNameError: No such robot; the message lists the valid names.
        ConfigError: Its files are malformed.
    """
    if name not in robot_names():
        raise UnknownNameError("robot", name, robot_names())
    folder = robots_dir() / name
    params = load_robot_parameters(folder / "robot.toml")
    if params.name != name:
        raise ConfigError(
            f"{folder / 'robot.toml'}: field 'name': is '{params.name}', expected '{name}'"
        )
    readable_file(folder / params.description, "robot description (MJCF)")
    return Robot(params=params, folder=folder)
