"""Robot parameter files: what a robot's MJCF description cannot say.

Each robot lives in ``robots/<name>/`` as two files:

- ``<name>.xml``: the MJCF description, read by both MuJoCo and Pinocchio (the one
  source of kinematics, inertias, joint ranges, gear ratios and motor torque limits).
- ``robot.toml``: this module's :class:`RobotParameters`: which body is the base,
  where the IMU sits, which bodies are feet, the foot contact points, the fall
  threshold, and each motor's low-level PD gains and torque-speed curve.

A second robot of a class is a new folder with these two files, never new code.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import Field, model_validator

from ridempc.tomlfile import load_checked
from ridempc.units import CheckedModel, NonNegative, Positive

__all__ = ["MotorParameters", "RobotParameters", "load_robot_parameters"]

PositiveFloat = Positive
NonNegativeFloat = NonNegative


class _Frozen(CheckedModel):
    """Strict numbers, no NaN, no unknown keys, immutable."""


class MotorParameters(_Frozen):
    """Low-level joint PD and torque-speed curve of one motor, as the motor driver runs it.

    The driver applies, at the physics rate,
    :math:`\\tau = \\tau_{ff} + k_p (q^* - q) + k_d (\\dot q^* - \\dot q)`,
    clipped to the torque-speed curve (:mod:`ridempc.robots.motor_curve`): the peak torque
    (the actuator's torque limit in the MJCF description) up to
    ``full_torque_fraction * speed_limit``, falling linearly to zero at ``speed_limit``, and
    reaching the joint ``torque_delay`` later.
    """

    kp: NonNegativeFloat = Field(description="Default joint stiffness [N m / rad].")
    kd: NonNegativeFloat = Field(description="Default joint damping [N m s / rad].")
    speed_limit: PositiveFloat = Field(
        description="No-load joint speed [rad / s]: the curve gives no torque at or beyond it."
    )
    full_torque_fraction: float = Field(
        gt=0.0,
        lt=1.0,
        description=(
            "Share of the no-load speed up to which the motor gives its peak torque (the "
            "curve's corner) [-]."
        ),
    )
    torque_delay: float = Field(
        ge=0.0,
        le=0.1,
        description="Time a torque command takes to reach the joint [s] (at most 0.1 s).",
    )


class RobotParameters(_Frozen):
    """Checked, immutable parameters of one robot (``robots/<name>/robot.toml``)."""

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9_-]*$")
    kind: str = Field(pattern=r"^(biped|quadruped)$")
    description: str = Field(description="MJCF file name, relative to the robot folder.")
    base_body: str = Field(description="Floating-base body (pelvis or trunk).")
    imu_site: str = Field(description="Site where the IMU is mounted.")
    foot_bodies: tuple[str, ...] = Field(
        min_length=1, description="Bodies allowed to touch the ground or a board."
    )
    contact_sites: tuple[str, ...] = Field(
        min_length=1, description="Foot contact points (sites), e.g. toe front/back."
    )
    encoder_joints: tuple[str, ...] = Field(
        default=(), description="Passive joints with encoders, besides the motor joints."
    )
    stand_keyframe: str = Field(default="stand", description="MJCF keyframe to start from.")
    stance_keyframes: dict[str, str] = Field(
        default_factory=dict,
        description="Per board name, the keyframe to start from on that board (else the stand).",
    )
    fall_height: PositiveFloat = Field(
        le=3.0,  # no legged robot's base stands 3 m high
        description="Base origin below this height over its support = fall [m].",
    )
    motors: dict[str, MotorParameters] = Field(
        min_length=1, description="Per motor, keyed by actuator name."
    )

    @model_validator(mode="after")
    def _contact_sites_unique(self) -> RobotParameters:
        if len(set(self.contact_sites)) != len(self.contact_sites):
            raise ValueError("contact_sites has duplicate entries")
        return self


def load_robot_parameters(path: Path) -> RobotParameters:
    """Read and check a ``robot.toml`` file.

    Raises:
        ConfigError: The file is missing, is not TOML, or a field is missing or wrong;
            the message names the file and the field.
    """
    return load_checked(path, RobotParameters, "robot parameter file")
