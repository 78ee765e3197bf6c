"""The Segway's checked parameters (``kind = "segway"`` in ``boards/<name>/board.toml``).

A miniPro-class personal transporter: one foot platform between two wheels on one axle, a
knee bar rising from the platform centre on a hinge about the forward axis with a centring
spring, and firmware that balances the platform in pitch and turns by the knee bar's angle.
Every figure is checked to be physical, so a missing or non-physical value is refused with
a :class:`~ridempc.errors.ConfigError` naming the field.
"""

from __future__ import annotations

from typing import Annotated, Literal, Self

from pydantic import Field, model_validator

from ridempc.boards.parameters import (
    Angle,
    BoardParameters,
    Clearance,
    GroundSpeed,
    Length,
    Mass,
    NonNegative,
    Positive,
    Real,
    Torque,
)
from ridempc.units import CheckedModel

__all__ = ["SegwayGains", "SegwayParameters", "SegwayReducedParameters"]

# A signed coefficient of the identified model (SI units): the committed ones are below
# 5e3; beyond 1e5 the fit has failed, whatever the board.
Coefficient = Annotated[Real, Field(ge=-1e5, le=1e5)]


class SegwayGains(CheckedModel):
    """The firmware's gains and limits (table ``[gains]``).

    Balance, total over both wheels (eq. in :mod:`ridempc.boards.segway.firmware`):
    :math:`T = k_p \\theta + k_d \\dot\\theta + k_v v + k_{push} \\max(|v| - v_{max}, 0)
    \\operatorname{sign} v`; turning: :math:`\\dot\\psi_{ref} = k_{turn} \\delta`,
    :math:`\\tau_{yaw} = k_{yaw} (\\dot\\psi_{ref} - \\dot\\psi)`.

    Attributes:
        pitch_kp: Platform pitch stiffness [N m / rad].
        pitch_kd: Platform pitch damping [N m s / rad].
        speed_kv: Wheel-speed feedback (the platform tilts back with speed) [N m s / m].
        pushback_gain: Extra speed feedback above ``top_speed`` (tilt-back) [N m s / m].
        turn_gain: Yaw-rate command per knee-bar angle [(rad/s) / rad].
        max_yaw_rate: Largest commanded yaw rate [rad/s].
        yaw_rate_kp: Differential wheel torque per yaw-rate error [N m s / rad].
    """

    pitch_kp: Positive
    pitch_kd: Positive
    speed_kv: NonNegative
    pushback_gain: NonNegative
    turn_gain: Positive
    max_yaw_rate: Positive
    yaw_rate_kp: Positive


class SegwayReducedParameters(CheckedModel):
    """Identified reduced model (table ``[reduced]``; see :mod:`ridempc.boards.segway.reduced`).

    Attributes:
        pitch_inertia: :math:`J_\\theta` [kg m^2].
        c1: Closed-loop pitch stiffness [N m / rad].
        c2: Closed-loop pitch damping [N m s / rad].
        c3: Pitch torque from the firmware's speed feedback [N m s / m].
        c4: Drive force per platform pitch [N / rad].
        c5: Drive force per forward speed (positive: speed feedback of the firmware) [N s / m].
        c6: Drive force per pitch rate (the firmware's pitch damping) [N s / rad].
        c7: Backward drive force per rider pitch torque (the lean's reaction) [N / (N m)].
        mass: :math:`m`, board and rider [kg].
        k_turn: Steady yaw rate per knee-bar angle [(rad/s) / rad].
        tau_turn: Time constant of the yaw rate's lag [s].
    """

    pitch_inertia: Positive
    c1: Positive
    c2: Positive
    c3: Coefficient
    c4: Positive
    c5: Coefficient
    c6: Coefficient = 0.0
    c7: Coefficient = 0.0
    mass: Positive
    k_turn: Positive
    tau_turn: Positive


class SegwayParameters(BoardParameters):
    """A Segway (miniPro class). Lengths [m], masses [kg], torques [N m], angles [deg].

    Attributes:
        wheel_radius: Tyre radius [m].
        wheel_width: Tyre width [m].
        wheel_mass: Mass of one wheel with its hub motor [kg].
        track_width: Distance between the wheels' mid-planes [m].
        chassis_mass: Platform frame, battery and electronics [kg].
        platform_length: Foot platform along the direction of travel (x) [m].
        platform_width: Foot platform across (y) [m].
        platform_thickness: Foot platform thickness [m].
        platform_height: Height of the platform's top surface over the ground [m].
        knee_bar_mass: Knee bar, column and pad [kg].
        knee_bar_height: Height of the knee pad's centre over the platform top [m].
        knee_bar_radius: Radius of the column [m].
        knee_bar_contact_from: Height over the platform top from which the column collides
            [m]; below it the column is visual only, so nothing standing on the platform
            (a dead weight, the feet) is pushed by its foot.
        knee_pad_width: Knee pad across (y) [m].
        knee_pad_depth: Knee pad along x [m].
        knee_pad_height: Knee pad's vertical extent [m].
        knee_bar_stiffness: Centring spring [N m / rad].
        knee_bar_damping: Hinge damping [N m s / rad].
        knee_bar_range: Travel of the knee bar to each side [deg].
        motor_torque_limit: Torque limit of each wheel motor [N m].
        top_speed: Speed above which the firmware tilts the platform back [m/s].
        gains: The firmware's gains (``[gains]``).
        reduced: Identified reduced model (``[reduced]``), if identified.
    """

    kind: Literal["segway"]
    wheel_radius: Length
    wheel_width: Length
    wheel_mass: Mass
    track_width: Length
    chassis_mass: Mass
    platform_length: Length
    platform_width: Length
    platform_thickness: Length
    platform_height: Length
    knee_bar_mass: Mass
    knee_bar_height: Length
    knee_bar_radius: Length
    knee_bar_contact_from: Clearance
    knee_pad_width: Length
    knee_pad_depth: Length
    knee_pad_height: Length
    knee_bar_stiffness: Positive
    knee_bar_damping: NonNegative
    knee_bar_range: Angle
    motor_torque_limit: Torque
    top_speed: GroundSpeed
    gains: SegwayGains
    reduced: SegwayReducedParameters | None = Field(default=None)

    @classmethod
    def firmware_gains(cls) -> dict[str, tuple[str, ...]]:
        """Every field of the ``[gains]`` table."""
        return {name: ("gains", name) for name in SegwayGains.model_fields}

    @model_validator(mode="after")
    def _fits_together(self) -> Self:
        if self.platform_thickness >= self.platform_height:
            raise ValueError("platform_thickness: the platform would reach the ground")
        if self.platform_width >= self.track_width - self.wheel_width:
            raise ValueError("platform_width: the platform would overlap the wheels")
        if self.knee_bar_contact_from >= self.knee_bar_height - self.knee_pad_height / 2:
            raise ValueError("knee_bar_contact_from: must be below the knee pad")
        if self.knee_pad_width >= self.track_width - self.wheel_width:
            raise ValueError("knee_pad_width: the pad would reach the wheels")
        return self
