"""Hovershoes parameter model: the checked figures of ``boards/<name>/board.toml``.

A pair of Hovershoes is two identical, independent one-wheel platforms (left on the +y
side, right on the -y side), each with its own wheel motor, IMU, wheel encoder and
firmware. Every figure is checked to be physical: a missing or non-physical value (zero
wheel radius, a deck below the top of its wheel, a wheel heavier than its shoe) is
refused with a :class:`~ridempc.errors.ConfigError` naming the field.
"""

from __future__ import annotations

from typing import Literal

from pydantic import ValidationInfo, field_validator

from ridempc.boards.parameters import (
    BoardParameters,
    Friction,
    GroundSpeed,
    Length,
    Mass,
    MotorSpeed,
    NonNegative,
    Positive,
    Torque,
)
from ridempc.units import CheckedModel

__all__ = ["HovershoesParameters", "HovershoesReducedParameters"]


class HovershoesReducedParameters(CheckedModel):
    """Identified parameters of the reduced model, paper eq. (4)-(8) (see ``reduced.py``).

    Attributes:
        J_theta: Pitch inertia of a loaded shoe [kg m^2].
        c1: Pitch stiffness of the shoe's closed loop [N m / rad].
        c2: Pitch damping of the shoe's closed loop [N m s / rad].
        J_psi: Yaw inertia of a loaded shoe [kg m^2].
        c3: Yaw damping of the tyre's ground contact [N m s / rad].
        c4: Forward force per radian of pitch [N / rad].
        m: Loaded mass (shoe and its load) the figures were identified with [kg].
    """

    J_theta: Positive
    c1: Positive
    c2: Positive
    J_psi: Positive
    c3: Positive
    c4: Positive
    m: Positive


class HovershoesParameters(BoardParameters):
    """One pair of Hovershoes (figures per shoe; both shoes are the same).

    Attributes:
        shoe_mass: Mass of one shoe, wheel included [kg].
        wheel_mass: Mass of the rotating part of the hub-motor wheel (tyre, rim, rotor) [kg].
        wheel_radius: Tyre radius [m].
        wheel_width: Tyre width [m]; the flat tread carries the shoe sideways.
        platform_length: Length of the foot deck along the direction of travel [m].
        platform_width: Width of the foot deck [m].
        platform_thickness: Thickness of the foot deck [m].
        platform_height: Height of the deck's top surface above the ground [m].
        shoe_spacing: Lateral distance between the two shoes' centres as built [m].
        platform_friction: Friction coefficient of the deck's grip pad [-].
        motor_torque_limit: Largest wheel-motor torque, at standstill [N m].
        motor_speed_limit: The motor's no-load speed [rad/s]: the torque it can give in the
            direction it turns falls linearly from ``motor_torque_limit`` to zero there.
        speed_limit: Ground speed at which the firmware starts tilting back [m/s].
        pitch_kp: Firmware pitch stiffness, wheel torque per radian of forward tilt [N m / rad].
        pitch_kd: Firmware pitch damping, wheel torque per rad/s of tilt rate [N m s / rad].
        tilt_back_gain: Nose-up tilt the firmware asks for per m/s above the speed limit
            [rad / (m / s)].
        reduced: Identified reduced model (``[reduced]`` table), or None.
    """

    kind: Literal["hovershoes"]
    shoe_mass: Mass
    wheel_mass: Mass
    wheel_radius: Length
    wheel_width: Length
    platform_length: Length
    platform_width: Length
    platform_thickness: Length
    platform_height: Length
    shoe_spacing: Length
    platform_friction: Friction
    motor_torque_limit: Torque
    motor_speed_limit: MotorSpeed
    speed_limit: GroundSpeed
    pitch_kp: Positive
    pitch_kd: NonNegative
    tilt_back_gain: NonNegative
    reduced: HovershoesReducedParameters | None = None

    @classmethod
    def firmware_gains(cls) -> dict[str, tuple[str, ...]]:
        """The shoe controller's gains, at the top level."""
        return {name: (name,) for name in ("pitch_kp", "pitch_kd", "tilt_back_gain")}

    @field_validator("wheel_mass")
    @classmethod
    def _wheel_lighter_than_shoe(cls, value: float, info: ValidationInfo) -> float:
        shoe = info.data.get("shoe_mass")
        if shoe is not None and value >= shoe:
            raise ValueError(f"must be below shoe_mass ({shoe} kg)")
        return value

    @field_validator("platform_height")
    @classmethod
    def _deck_above_wheel(cls, value: float, info: ValidationInfo) -> float:
        radius = info.data.get("wheel_radius")
        thickness = info.data.get("platform_thickness")
        if radius is not None and thickness is not None and value - thickness <= 2.0 * radius:
            raise ValueError(
                f"the deck's underside ({value} - {thickness} m) must clear the top of the "
                f"wheel (2 x {radius} m)"
            )
        return value

    @field_validator("shoe_spacing")
    @classmethod
    def _shoes_apart(cls, value: float, info: ValidationInfo) -> float:
        width = info.data.get("platform_width")
        if width is not None and value <= width:
            raise ValueError(f"must exceed platform_width ({width} m), or the shoes overlap")
        return value

    @field_validator("speed_limit")
    @classmethod
    def _below_no_load_speed(cls, value: float, info: ValidationInfo) -> float:
        radius = info.data.get("wheel_radius")
        no_load = info.data.get("motor_speed_limit")
        if radius is not None and no_load is not None and value >= no_load * radius:
            raise ValueError(
                f"must be below the motor's no-load ground speed ({no_load * radius:.3g} m/s)"
            )
        return value

    @field_validator("platform_sites", "ground_bodies")
    @classmethod
    def _two_shoes(cls, value: tuple[str, ...]) -> tuple[str, ...]:
        if len(value) != 2:
            raise ValueError("a pair of Hovershoes has two entries: left (+y) then right (-y)")
        return value
