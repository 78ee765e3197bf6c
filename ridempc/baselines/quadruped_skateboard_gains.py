"""Gains of the quadruped's skateboard PD (``quadruped_skateboard.toml``), checked on load.

Every number of the control law in :mod:`ridempc.baselines.quadruped_skateboard` lives in the
file; nothing is tuned in code. Unknown keys, missing fields, wrong types and non-physical
values are refused with :class:`~ridempc.errors.ConfigError` naming the file and the field.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field

from ridempc.baselines.gains_files import pair_gains_file
from ridempc.tomlfile import load_checked
from ridempc.units import CheckedModel, NonNegative, Positive, Real

__all__ = [
    "DEFAULT_GAINS_FILE",
    "ContactGains",
    "ForceGains",
    "JointGainSet",
    "JointGains",
    "Posture",
    "QuadrupedSkateboardGains",
    "RollGains",
    "SteeringGains",
    "gains_file",
    "load_quadruped_skateboard_gains",
]

DEFAULT_GAINS_FILE = Path(__file__).with_name("quadruped_skateboard.toml")  # CyberDog2's figures


class _Frozen(CheckedModel):
    """Strict numbers, no NaN, no unknown keys, immutable."""


class Posture(_Frozen):
    """The trunk's pose over the feet; ``height`` left out is held from the first packet."""

    height: Annotated[Real, Field(gt=0.1, lt=0.35)] | None = Field(
        None, description="Trunk origin above the feet's centroid [m]."
    )
    com_x: Annotated[Real, Field(ge=-0.08, le=0.08)] = Field(
        0.0, description="Centre of mass ahead of the feet's centroid [m]."
    )
    pitch: Annotated[Real, Field(ge=-0.3, le=0.3)] = Field(
        0.0, description="Trunk pitch, positive nose down [rad]."
    )
    max_correction: Annotated[Real, Field(gt=0.0, le=0.1)] = Field(
        description="Largest trunk displacement asked for in one tick [m]."
    )
    max_rotation: Annotated[Real, Field(gt=0.0, le=0.5)] = Field(
        description="Largest trunk rotation asked for in one tick [rad]."
    )


class RollGains(_Frozen):
    """Deck roll by the lateral shift of the centre of mass, to the right (-y) by

    :math:`u = \\frac{K_B \\varphi^* + B_B \\dot\\varphi^* + I_{Bx} \\ddot\\varphi^*}{m g}
    + k_p e + k_d \\dot e + k_i \\textstyle\\int e\\,dt`, :math:`e = \\varphi^* - \\hat\\varphi`.
    """

    feedforward: Annotated[Real, Field(ge=0.0, le=2.0)] = Field(
        description="Scale of the reduced-model feedforward [-] (1 = the identified model)."
    )
    kp: NonNegative = Field(description="Shift per rad of roll error [m/rad].")
    kd: NonNegative = Field(description="Shift per rad/s of roll-rate error [m s/rad].")
    ki: NonNegative = Field(description="Shift per rad s of integrated roll error [m/(rad s)].")
    integral_limit: NonNegative = Field(description="Bound of the integral term [m].")
    damping: NonNegative = Field(
        description="Deck-mode damping by the feet's load difference, "
        ":math:`\\Delta f_i = -D \\dot{\\hat\\varphi}\\, y_i / \\sum y_j^2` [N m s/rad]."
    )
    max_shift: Annotated[Real, Field(gt=0.0, le=0.1)] = Field(
        description="Bound of the shift, inside the feet's lateral half-spacing [m]."
    )
    feedback_bandwidth: Positive = Field(
        description="Natural frequency of the critically damped filter on the feedback "
        "shift [rad/s]; well below the deck's own (about 20 rad/s)."
    )
    rate_filter: NonNegative = Field(
        description="Time constant of the low-pass on the estimated roll rate [s]."
    )
    follow_bandwidth: Positive = Field(
        description="Natural frequency of the commanded shift's follower [rad/s]."
    )
    max_acceleration: Positive = Field(
        description="Bound of the commanded shift's acceleration [m/s^2]."
    )


class SteeringGains(_Frozen):
    """Yaw-rate command to a deck-roll reference by eq. (14), when the board rolls along."""

    min_speed: Positive = Field(description="Below this forward speed, no steering [m/s].")
    max_roll: Annotated[Real, Field(gt=0.0, le=0.2)] = Field(
        description="Bound of the steering roll and of the whole roll reference [rad]."
    )


class JointGains(_Frozen):
    """One joint's PD as sent to its motor driver."""

    kp: NonNegative = Field(description="Stiffness [N m / rad].")
    kd: NonNegative = Field(description="Damping [N m s / rad].")


class JointGainSet(_Frozen):
    """Per joint of each leg. The abad's gains, which set the foot's sideways stiffness, are
    scaled per leg by its share of the weight, :math:`\\mathrm{clip}(4 f_i / m g)`, so that a
    sideways error loads the feet in proportion to their grip."""

    abad: JointGains
    hip: JointGains
    knee: JointGains
    abad_scale_min: Annotated[Real, Field(gt=0.0, le=1.0)] = Field(
        description="Least scale of a leg's abad gains [-]."
    )
    abad_scale_max: Annotated[Real, Field(ge=1.0, le=4.0)] = Field(
        description="Largest scale of a leg's abad gains [-]."
    )


class ForceGains(_Frozen):
    """Gravity feedforward: the weight shared by the feet, mapped by :math:`J^\\top`."""

    weight_fraction: Annotated[Real, Field(ge=0.0, le=1.2)] = Field(
        description="Fraction of the robot's weight fed forward [-]."
    )
    min_load: NonNegative = Field(description="Floor of each foot's vertical load [N].")


class ContactGains(_Frozen):
    """How far the feet press into what they stand on."""

    compliance: NonNegative = Field(
        description="Sinking of a foot centre per newton of vertical load [m/N]."
    )


class QuadrupedSkateboardGains(_Frozen):
    """Checked, immutable gains of the quadruped's skateboard PD."""

    rate_hz: Positive = Field(500.0, description="Controller rate [Hz].")
    posture: Posture
    roll: RollGains
    steering: SteeringGains
    joints: JointGainSet
    force: ForceGains
    contact: ContactGains


def load_quadruped_skateboard_gains(
    path: Path | str = DEFAULT_GAINS_FILE,
) -> QuadrupedSkateboardGains:
    """Read and check a gain file.

    Raises:
        ConfigError: The file is missing, is not TOML, or a field is missing or wrong;
            the message names the file and the field.
    """
    return load_checked(Path(path), QuadrupedSkateboardGains, "quadruped skateboard gain file")


def gains_file(robot: str, board: str) -> Path:
    """The gains file of ``robot`` on ``board``: the one its pair file names (``pd_gains``:
    figures that depend on the robot's mass, its stance and its feet), else the shared
    :data:`DEFAULT_GAINS_FILE`.

    Raises:
        ConfigError: The pair file is malformed.
    """
    return pair_gains_file(robot, board, DEFAULT_GAINS_FILE)
