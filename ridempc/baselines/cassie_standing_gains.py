"""Gains of Cassie's standing controller (``cassie_standing.toml``), checked on load.

The file holds every number of the control law in
:mod:`ridempc.baselines.cassie_standing`; nothing is tuned in code. It is read into the
frozen :class:`CassieStandingGains`; unknown keys, missing fields, wrong types and
non-physical values are refused with :class:`~ridempc.errors.ConfigError` naming the file and
the field.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field, model_validator

from ridempc.tomlfile import load_checked
from ridempc.units import CheckedModel, NonNegative, Positive, Real

__all__ = [
    "DEFAULT_GAINS_FILE",
    "CassieStandingGains",
    "ComXGains",
    "JointGains",
    "JointGainSet",
    "LegLimits",
    "Posture",
    "RollGains",
    "load_standing_gains",
]

DEFAULT_GAINS_FILE = Path(__file__).with_name("cassie_standing.toml")


class _Frozen(CheckedModel):
    """Strict numbers, no NaN, no unknown keys, immutable."""


class Posture(_Frozen):
    """The standing posture; a field left out is read from the first sensor packet."""

    leg_length: Annotated[Real, Field(gt=0.3, lt=1.05)] | None = Field(
        None, description="Mean virtual leg length [m]; sets the standing height."
    )
    hip_roll: Annotated[Real, Field(ge=0.0, le=0.3)] | None = Field(
        None, description="Outward hip roll of each leg [rad] (+ left, - right)."
    )
    hip_yaw: Annotated[Real, Field(ge=-0.3, le=0.3)] | None = Field(
        None, description="Hip yaw of each leg [rad] (mirrored: + left, - right)."
    )
    pitch: Annotated[Real, Field(ge=-0.5, le=0.5)] = Field(
        0.0, description="Pelvis pitch target [rad], positive nose down."
    )


class ComXGains(_Frozen):
    """CoM x by toe pitch: the centre-of-pressure law.

    :math:`p_x^* = x + k_p (x - x^*) + k_d \\dot x` relative to the support centre.
    """

    target: Annotated[Real, Field(ge=-0.08, le=0.08)] = Field(
        description="CoM x target relative to the feet's support centre [m]."
    )
    kp: NonNegative = Field(description="CoP lead per metre of CoM error [-].")
    kd: NonNegative = Field(description="CoP lead per m/s of CoM velocity [s].")
    cop_margin: Annotated[Real, Field(ge=0.0, le=0.05)] = Field(
        description="The CoP stays this far inside each foot's contact line [m]."
    )
    filter_hz: NonNegative = Field(
        description="Low-pass cut-off on the CoM offset and velocity [Hz]; 0 = none."
    )


class RollGains(_Frozen):
    """Roll by the leg-length difference: :math:`L_{L,R} = \\bar L \\mp u`,
    :math:`u = k_p (\\phi - \\phi^*) + k_d \\dot\\phi + k_i \\int (\\phi - \\phi^*) dt`."""

    kp: NonNegative = Field(description="Half leg-length difference per rad of roll [m/rad].")
    kd: NonNegative = Field(description="Per rad/s of roll rate [m s/rad].")
    ki: NonNegative = Field(0.0, description="Per rad s of integrated roll [m/(rad s)].")
    integral_limit: NonNegative = Field(0.03, description="Bound of the integral term [m].")
    filter_hz: NonNegative = Field(
        description="Low-pass cut-off on the IMU roll and roll rate [Hz]; 0 = none."
    )


class JointGains(_Frozen):
    """One joint's PD as sent to its motor driver."""

    kp: NonNegative = Field(description="Stiffness [N m / rad].")
    kd: NonNegative = Field(description="Damping [N m s / rad].")


class JointGainSet(_Frozen):
    """Per joint of each leg. The hip pitch's PD acts on the pelvis pitch error (its target
    follows the measured leg angle), the knee's on the leg length, the toe's target is its
    measured angle (the toe is driven by the CoP feedforward; ``kd`` damps it)."""

    hip_roll: JointGains
    hip_yaw: JointGains
    hip_pitch: JointGains
    knee: JointGains
    toe: JointGains


class LegLimits(_Frozen):
    """Bounds on the commanded virtual leg length and its rate."""

    min_length: Annotated[Real, Field(gt=0.3)] = Field(description="[m]")
    max_length: Annotated[Real, Field(lt=1.05)] = Field(description="[m]")
    max_speed: Positive = Field(description="Fastest change of the mean leg length [m/s].")

    @model_validator(mode="after")
    def _ordered(self) -> LegLimits:
        if self.min_length >= self.max_length:
            raise ValueError("min_length must be below max_length")
        return self


class CassieStandingGains(_Frozen):
    """Checked, immutable gains of the standing controller."""

    rate_hz: Positive = Field(500.0, description="Controller rate [Hz].")
    posture: Posture = Posture()
    com_x: ComXGains
    roll: RollGains
    joints: JointGainSet
    legs: LegLimits


def load_standing_gains(path: Path | str = DEFAULT_GAINS_FILE) -> CassieStandingGains:
    """Read and check a standing-controller gain file.

    Raises:
        ConfigError: The file is missing, is not TOML, or a field is missing or wrong;
            the message names the file and the field.
    """
    return load_checked(Path(path), CassieStandingGains, "standing gain file")
