"""Checked numbers for every file a user can give or edit, and the model base that uses them.

TOML and JSON hand pydantic Python values, and pydantic's lax mode would turn
``velocity = "1.0"`` or ``velocity = true`` into 1.0, and would take ``nan`` and ``inf``
(both valid TOML). The types here refuse all of that: a :data:`Real` is an ``int`` or a
``float`` (never a ``bool`` or a ``str``) and finite; a :data:`Count` is an ``int``; a
:data:`Flag` is a ``bool`` (never ``1`` or ``"yes"``). Tuple
fields stay lax, so a TOML list still fills a tuple, but each element is checked by its own
strict type.

Every model of a scenario, board, robot, gain or library file derives from
:class:`CheckedModel` and declares its numbers with these types, so the check cannot be
forgotten field by field.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import AllowInfNan, BaseModel, BeforeValidator, ConfigDict, Field, Strict

__all__ = [
    "CHECKED",
    "MAX_DURATION",
    "MAX_RATE_HZ",
    "MIN_DURATION",
    "Angle",
    "CheckedModel",
    "Count",
    "Duration",
    "Flag",
    "Friction",
    "NonNegative",
    "NonNegativeCount",
    "Positive",
    "PositiveCount",
    "Rate",
    "Real",
    "RideDuration",
    "Time",
]

# The longest ride, scenario or ``--duration`` [s]: an hour is far beyond any manoeuvre and
# keeps a ride's log (hundreds of channels at 1 kHz) within memory.
MAX_DURATION: float = 3600.0
# The shortest ride [s]: one sample of the 100 Hz log; a shorter one records nothing.
MIN_DURATION: float = 0.01
# The fastest loop any file may ask for [Hz]: a physics step below 0.1 ms buys nothing.
MAX_RATE_HZ: float = 10_000.0


def _plain_number(value: Any) -> Any:
    """NumPy numbers (a fit's figures, a build's counters) as Python ones; else unchanged."""
    return value.item() if isinstance(value, np.integer | np.floating) else value


Real = Annotated[float, Strict(), AllowInfNan(False), BeforeValidator(_plain_number)]
"""A finite number given as an int or a float, never as a bool or a string."""
Positive = Annotated[Real, Field(gt=0.0)]
NonNegative = Annotated[Real, Field(ge=0.0)]
Count = Annotated[int, Strict(), BeforeValidator(_plain_number)]
"""An integer given as an int (a float, a bool or a string is refused)."""
PositiveCount = Annotated[Count, Field(gt=0)]
NonNegativeCount = Annotated[Count, Field(ge=0)]
Time = Annotated[Real, Field(ge=0.0, le=MAX_DURATION, description="[s]")]
"""An instant of a ride [s], from its start to the longest ride."""
Duration = Annotated[Real, Field(gt=0.0, le=MAX_DURATION, description="[s]")]
"""A positive span of time [s], at most the longest ride."""
RideDuration = Annotated[Real, Field(ge=MIN_DURATION, le=MAX_DURATION, description="[s]")]
"""The length of a ride [s], from one log sample to the longest ride."""
Rate = Annotated[Real, Field(gt=0.0, le=MAX_RATE_HZ, description="[Hz]")]
# Rubber on grip tape or asphalt stays below 2; 10 is beyond any real pair of surfaces.
Friction = Annotated[Real, Field(gt=0.0, le=10.0, description="[-]")]
Angle = Annotated[Real, Field(gt=0.0, lt=90.0, description="[deg], in (0, 90)")]
Flag = Annotated[bool, Strict()]
"""``true`` or ``false``, never a number or a string such as ``"yes"``."""

CHECKED = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


class CheckedModel(BaseModel):
    """Immutable, no unknown keys, no NaN or infinity even in a field typed plain ``float``."""

    model_config = CHECKED
