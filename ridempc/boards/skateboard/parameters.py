"""The skateboard's checked parameters (``boards/<name>/board.toml`` of kind ``skateboard``).

A deck on two trucks. Each truck pivots about its kingpin axis, which lies in the deck's
vertical x-z plane, passes through the axle centre and leans from the deck normal by the
rake angle :math:`\\gamma` (skateboard paper, Fig. 4 and eq. 11), against a rubber
bushing modelled as a torsional spring-damper about that axis. Four passive wheels roll
with a Coulomb rolling resistance on their bearings.

Geometry, masses and the roll limit are public figures (see the board's README); the rake,
bushing and rolling-resistance figures are chosen, and the ``[reduced]`` table holds the
reduced model identified from simulated experiments (:mod:`.identify`).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from ridempc.boards.parameters import (
    Angle,
    BoardParameters,
    Length,
    Mass,
    NonNegative,
    Positive,
    Real,
)
from ridempc.units import CheckedModel

__all__ = ["SkateboardParameters", "SkateboardReducedParameters"]


class SkateboardReducedParameters(CheckedModel):
    """Identified reduced model: deck roll eq. (6)-(7) and the kinematic gain of eq. (14).

    Attributes:
        roll_inertia: Deck roll inertia :math:`I_{Bx}` [kg m^2].
        roll_stiffness: Bushing roll stiffness :math:`K_B` [N m / rad].
        roll_damping: Bushing roll damping :math:`B_B` [N m s / rad].
        steer_gain: Yaw rate per forward speed and sine of roll,
            :math:`1 / K_{board} = (\\cot\\gamma_f + \\cot\\gamma_r) / L` [1 / m].
    """

    roll_inertia: Positive
    roll_stiffness: Positive
    roll_damping: NonNegative
    steer_gain: Positive


class SkateboardParameters(BoardParameters):
    """A skateboard: deck, two raked trucks on bushings, four passive wheels.

    Attributes:
        deck_length: Deck length along x [m].
        deck_width: Deck width along y [m].
        deck_thickness: Deck thickness [m].
        deck_mass: Deck mass [kg].
        height: Overall height, ground to the deck's top surface [m].
        wheelbase: Distance between the two axles, :math:`L = l_f + l_r` [m].
        truck_width: Overall truck width, outer wheel face to outer wheel face [m].
        truck_mass: Mass of one truck (hanger, baseplate, kingpin) [kg].
        wheel_radius: Wheel radius [m].
        wheel_width: Wheel width [m].
        wheel_mass: Mass of one wheel [kg].
        rake_front: Front rake :math:`\\gamma_f`, kingpin axis from the deck normal [deg].
        rake_rear: Rear rake :math:`\\gamma_r`, kingpin axis from the deck normal [deg].
        bushing_stiffness: Torsional stiffness of one truck's bushings about its kingpin
            axis [N m / rad].
        bushing_damping: Torsional damping of one truck's bushings [N m s / rad].
        roll_limit: Deck roll at which the bushings bottom out [rad].
        wheel_friction_torque: Coulomb rolling-resistance torque of one wheel [N m]
            (:math:`C_{rr} N r` at the nominal load).
        wheel_damping: Viscous bearing damping of one wheel [N m s / rad].
        reduced: The identified reduced model, or None before identification.
    """

    kind: Literal["skateboard"]
    deck_length: Length
    deck_width: Length
    deck_thickness: Length
    deck_mass: Mass
    height: Length
    wheelbase: Length
    truck_width: Length
    truck_mass: Mass
    wheel_radius: Length
    wheel_width: Length
    wheel_mass: Mass
    rake_front: Angle
    rake_rear: Angle
    bushing_stiffness: Positive
    bushing_damping: NonNegative
    roll_limit: Real = Field(gt=0.0, lt=0.5, description="[rad]")
    wheel_friction_torque: NonNegative
    wheel_damping: NonNegative
    reduced: SkateboardReducedParameters | None = None

    @model_validator(mode="after")
    def _geometry_fits(self) -> SkateboardParameters:
        if self.height <= 2.0 * self.wheel_radius + self.deck_thickness:
            raise ValueError(
                "height must exceed the wheel diameter plus the deck thickness "
                f"({2.0 * self.wheel_radius + self.deck_thickness:.3f} m)"
            )
        if self.wheelbase + 2.0 * self.wheel_radius >= self.deck_length:
            raise ValueError("wheelbase plus a wheel diameter must fit under the deck_length")
        if self.truck_width <= 2.0 * self.wheel_width:
            raise ValueError("truck_width must exceed two wheel widths")
        return self

    @property
    def track(self) -> float:
        """Distance between the wheel centres of one truck [m]."""
        return self.truck_width - self.wheel_width
