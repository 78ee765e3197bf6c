"""Gains of Cassie's Hovershoe controller (``cassie_hovershoes.toml``), checked on load.

The file holds every number of the decoupled controller of the hovershoe paper, eq.
(10)-(27), in :mod:`ridempc.baselines.cassie_hovershoes` and
:mod:`ridempc.baselines.hovershoe_laws`, and the standing controller's own gains
(``[standing]``, the schema of :mod:`ridempc.baselines.cassie_standing_gains`) as tuned
for standing on the shoes; nothing is tuned in code. Unknown keys, missing fields, wrong
types and non-physical values are refused with :class:`~ridempc.errors.ConfigError` naming
the file and the field.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field

from ridempc.baselines.cassie_standing_gains import CassieStandingGains
from ridempc.tomlfile import load_checked
from ridempc.units import CheckedModel, Flag, NonNegative, Positive, Real

__all__ = [
    "DEFAULT_GAINS_FILE",
    "CassieHovershoesGains",
    "LegAngleGains",
    "ToeDampingGains",
    "TurningGains",
    "VelocityGains",
    "XAxisGains",
    "YAxisGains",
    "load_hovershoes_gains",
]

DEFAULT_GAINS_FILE = Path(__file__).with_name("cassie_hovershoes.toml")


class _Frozen(CheckedModel):
    """Strict numbers, no NaN, no unknown keys, immutable."""


class XAxisGains(_Frozen):
    """x-axis controller, eq. (10)-(13): the shoes' relative x by differential toe pitch."""

    kp: NonNegative = Field(description="K_p^x: toe-angle difference per metre of stagger [rad/m].")
    max_toe_difference: Positive = Field(
        description="Bound of the desired toe-angle difference [rad]."
    )
    kp_toe: NonNegative = Field(description="K_p^dtoe: inner loop stiffness [N m/rad].")
    kd_toe: NonNegative = Field(description="K_d^dtoe: inner loop damping [N m s/rad].")
    max_torque: Positive = Field(description="Bound of u_5^dtoe [N m].")
    filter_hz: NonNegative = Field(
        description="Low-pass cut-off on the stagger and the toe-angle difference [Hz]; 0 = none."
    )


class YAxisGains(_Frozen):
    """y-axis controller, eq. (14)-(16): each foot's y at +-y_offset by hip yaw."""

    kp: NonNegative = Field(description="K_p^y: hip yaw per metre of foot y error [rad/m].")
    max_hip_yaw: Annotated[Real, Field(gt=0.0, le=0.39)] = Field(
        description="Bound of the hip-yaw target about the posture [rad] (joint range 0.39)."
    )
    kp_hip_yaw: NonNegative = Field(description="K_p^q2: hip-yaw stiffness [N m/rad].")
    filter_hz: NonNegative = Field(description="Low-pass cut-off on the feet's y [Hz]; 0 = none.")
    spread_by_hip_roll: Flag = Field(
        description="Move the standing hip-roll posture with the commanded y_offset change."
    )


class VelocityGains(_Frozen):
    """Velocity controller, eq. (17): the CoM x target from the estimated speed."""

    kp: NonNegative = Field(description="K_p^vel: CoM lead per m/s of speed error [s].")
    max_com_x: Positive = Field(description="Bound of the CoM x target [m].")
    filter_hz: NonNegative = Field(
        description="Low-pass cut-off on the estimated speed [Hz]; 0 = none."
    )


class TurningGains(_Frozen):
    """Turning controller, eq. (18)-(22): hip yaw, differential toe and lean."""

    kp_yaw: NonNegative = Field(description="K_p^yaw: hip-yaw torque per rad/s [N m s/rad].")
    kp_pitch: NonNegative = Field(description="K_p^pitch: toe torque per rad/s [N m s/rad].")
    ki_pitch: NonNegative = Field(
        description="Integral of the yaw-rate error into the toe torque [N m/rad] (0: the "
        "paper's P law; the paper suggests integral feedback for the steady error)."
    )
    integral_limit: NonNegative = Field(
        description="Bound of the integral term's toe torque [N m]."
    )
    max_toe_torque: Positive = Field(description="Bound of u_5^turn [N m].")
    kp_shift: NonNegative = Field(description="K_p^shift: CoM y shift per lean L theta [-].")
    max_com_y: Positive = Field(description="Bound of the CoM y target [m].")
    filter_hz: NonNegative = Field(
        description="Low-pass cut-off on the estimated yaw rate [Hz]; 0 = none."
    )


class LegAngleGains(_Frozen):
    """The nominal controller's hold of equal leg angles (part of eq. 25's :math:`\\tilde u_3`):
    :math:`u_{3,L/R} \\mathrel{+}= \\mp k_p (\\theta_L - \\theta_R) / 2` on the hip pitches."""

    kp: NonNegative = Field(description="Stiffness against the leg-angle difference [N m/rad].")


class ToeDampingGains(_Frozen):
    """The toe damping term of eq. (27), u_5^damping = -k_d q7', run by the toe's driver."""

    kd: NonNegative = Field(description="Toe damping [N m s/rad].")


class FlightGains(_Frozen):
    """A shoe in the air (:mod:`ridempc.baselines.hovershoe_flight`): its ankle held, the CoP
    law's CoM reading held, while the leg's shin spring says the foot is unloaded."""

    unloaded_shin: Annotated[Real, Field(ge=0.0, le=0.1)] = Field(
        0.0,
        description="Shin deflection below which a foot is unloaded [rad]; 0 = never.",
    )
    kp_toe: NonNegative = Field(
        0.0, description="Stiffness holding an unloaded foot at its last pitch [N m/rad]."
    )
    extend_speed: NonNegative = Field(
        0.0, description="Speed at which an unloaded leg reaches down [m/s]; 0 = never."
    )
    max_extension: NonNegative = Field(0.0, description="Longest reach down [m].")
    reach_delay: NonNegative = Field(
        0.0, description="How long a foot is unloaded before its leg reaches down [s]."
    )


class CassieHovershoesGains(_Frozen):
    """Checked, immutable gains of the Hovershoe controller."""

    x_axis: XAxisGains
    y_axis: YAxisGains
    velocity: VelocityGains
    turning: TurningGains
    toe_damping: ToeDampingGains
    leg_angle: LegAngleGains
    flight: FlightGains = FlightGains()
    standing: CassieStandingGains


def load_hovershoes_gains(path: Path | str = DEFAULT_GAINS_FILE) -> CassieHovershoesGains:
    """Read and check a Hovershoe-controller gain file.

    Raises:
        ConfigError: The file is missing, is not TOML, or a field is missing or wrong;
            the message names the file and the field.
    """
    return load_checked(Path(path), CassieHovershoesGains, "hovershoe gain file")
