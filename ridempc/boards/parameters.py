"""Board parameter files (``boards/<name>/board.toml``): the board's one description.

A board's MuJoCo body tree is built from these checked figures by its kind's builder
(see :mod:`ridempc.boards.kinds`), and Pinocchio reads the MJCF that builder produces, so
a second board of a kind (a bigger skateboard) is a new parameter file, not new code.

Fields common to every board live in :class:`BoardParameters`; each kind subclasses it
with its own figures (wheel radius, rake angles, ...), every one checked to be physical.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

from pydantic import Field

from ridempc.tomlfile import read_toml, validate
from ridempc.units import Angle, CheckedModel, Friction, NonNegative, Positive, Rate, Real

__all__ = [
    "Angle",
    "BoardParameters",
    "Clearance",
    "Friction",
    "GroundSpeed",
    "Length",
    "Mass",
    "MotorSpeed",
    "NonNegative",
    "Positive",
    "Real",
    "Torque",
    "read_board_toml",
    "validate_board_parameters",
]


# Upper bounds of a board's figures: each well beyond any rideable board, so that a value
# past one is a slip of units (millimetres for metres, grams for kilograms), not a board.
# A board part heavier than 200 kg (a whole Segway miniPro is 13 kg).
Mass = Annotated[Positive, Field(le=200.0, description="[kg]")]
# A board dimension beyond 2 m (a longboard's deck is 1.2 m).
Length = Annotated[Positive, Field(le=2.0, description="[m]")]
Clearance = Annotated[NonNegative, Field(le=2.0, description="[m]")]
# A wheel motor above 500 N m (hub motors of personal transporters give tens of N m).
Torque = Annotated[Positive, Field(le=500.0, description="[N m]")]
# A ground speed above 20 m/s (personal transporters stop near 6 m/s).
GroundSpeed = Annotated[Positive, Field(le=20.0, description="[m/s]")]
# A motor turning faster than 1000 rad/s (10,000 rpm) at the wheel.
MotorSpeed = Annotated[Positive, Field(le=1000.0, description="[rad/s]")]


class BoardParameters(CheckedModel):
    """What every board states.

    Attributes:
        name: Board name (its folder's name).
        kind: Which builder, firmware and reduced model it uses (``hovershoes``, ...).
        firmware_hz: Rate of the board's firmware [Hz] (a divisor of the physics rate).
        platform_sites: Sites at the top centre of each platform, where the rider stands:
            one for a rigid board, one per foot for independent platforms (Hovershoes).
        ground_bodies: Bodies allowed to touch the ground (the wheels); any other board
            body on the ground means the board fell.
        dead_weight_robot: Robot whose mass the default dead weight has.
    """

    name: str = Field(pattern=r"^[a-z0-9][a-z0-9_-]*$")
    kind: str
    firmware_hz: Rate
    platform_sites: tuple[str, ...] = Field(min_length=1)
    ground_bodies: tuple[str, ...] = Field(min_length=1)
    dead_weight_robot: str

    @classmethod
    def firmware_gains(cls) -> dict[str, tuple[str, ...]]:
        """The gains the kind's firmware reads, by name: where each sits in the parameters
        (a path of field names), for a scenario's ``firmware_gain`` change. None here: a
        board without electronics (the skateboard) has no gains."""
        return {}


def read_board_toml(path: Path) -> dict[str, Any]:
    return read_toml(path, "board parameter file")


def validate_board_parameters(
    path: Path, raw: dict[str, Any], model: type[BoardParameters]
) -> BoardParameters:
    """Check ``raw`` against a kind's parameter model, naming the bad field on failure."""
    return validate(path, raw, model)
