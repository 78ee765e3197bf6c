"""Gains of Cassie's Segway rider (``cassie_segway.toml``), checked on load.

The file holds every number of the control law in :mod:`ridempc.baselines.cassie_segway`;
nothing is tuned in code. Its ``[standing]`` table lists only what differs from the
standing controller's gains (``cassie_standing.toml``: the crouched posture and the feet's
lowered feedback gains, as the paper says); it is laid over that file and the whole is
checked as :class:`~ridempc.baselines.cassie_standing_gains.CassieStandingGains`. Unknown
keys, missing fields, wrong types and non-physical values are refused with
:class:`~ridempc.errors.ConfigError` naming the file and the field (``standing.com_x.kp``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

from pydantic import Field

from ridempc.baselines.cassie_standing_gains import DEFAULT_GAINS_FILE as STANDING_GAINS_FILE
from ridempc.baselines.cassie_standing_gains import CassieStandingGains
from ridempc.errors import ConfigError
from ridempc.tomlfile import read_toml, validate
from ridempc.units import CheckedModel, NonNegative, Positive, Real

__all__ = [
    "DEFAULT_GAINS_FILE",
    "CassieSegwayGains",
    "LoopGains",
    "MountGains",
    "load_segway_gains",
]

DEFAULT_GAINS_FILE = Path(__file__).with_name("cassie_segway.toml")


class _Frozen(CheckedModel):
    """Strict numbers, no NaN, no unknown keys, immutable."""


class LoopGains(_Frozen):
    """One outer loop: a command-rate error turned into a CoM target shift [m],

    :math:`s^* = s_0 + k_{ff} r^* + k_{\\dot{ff}} \\dot r^* + k_p e + k_i \\textstyle\\int e\\,dt`,
    :math:`e = r^* - \\hat r`, clamped to :math:`s_0 \\pm` ``max_shift`` and moved at most at
    ``max_rate``.
    """

    # The shift is clamped to max_shift (<= 0.12 m): a feedforward above 1 m per unit of
    # command would saturate it at an eighth of a unit.
    feedforward: Annotated[Real, Field(ge=-1.0, le=1.0)] = Field(
        description="Shift per unit of command [m per m/s or rad/s]."
    )
    feedforward_rate: Annotated[Real, Field(ge=-1.0, le=1.0)] = Field(
        description="Shift per unit of the command's rate [m per m/s^2 or rad/s^2]."
    )
    kp: NonNegative = Field(description="Shift per unit of error [m per m/s or rad/s].")
    ki: NonNegative = Field(description="Shift per unit of integrated error [m per m or rad].")
    integral_limit: NonNegative = Field(description="Bound of the integral term [m].")
    max_shift: Annotated[Real, Field(gt=0.0, le=0.12)] = Field(
        description="Bound of the shift about the standing target [m]."
    )
    max_rate: Positive = Field(description="Fastest change of the shift [m/s].")
    filter_hz: NonNegative = Field(
        description="Low-pass cut-off on the estimated rate [Hz]; 0 = none."
    )


class MountGains(_Frozen):
    """Getting into the riding posture from the stance the ride starts in."""

    spread_time: Annotated[Real, Field(ge=0.0, le=5.0)] = Field(
        description="Time to turn the hip roll to the posture's before crouching [s]."
    )


class CassieSegwayGains(_Frozen):
    """Checked, immutable gains of the Segway rider.

    Attributes:
        standing: The standing controller's gains with the Segway's changes laid over.
        mount: Getting into the crouch.
        velocity: Forward speed by the CoM x target (Segway paper IV-B).
        turning: Yaw rate by the sideways CoM shift, the legs leaning into the knee bar.
    """

    standing: CassieStandingGains
    mount: MountGains
    velocity: LoopGains
    turning: LoopGains


def _overlay(base: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """``base`` with the tables of ``changes`` merged in, recursively."""
    merged = dict(base)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = _overlay(merged[key], value)
        else:
            merged[key] = value
    return merged


def load_segway_gains(
    path: Path | str = DEFAULT_GAINS_FILE,
    standing: Path | str = STANDING_GAINS_FILE,
) -> CassieSegwayGains:
    """Read and check the Segway rider's gain file, laid over the standing gains.

    Args:
        path: The Segway rider's gain file.
        standing: The standing controller's gain file its ``[standing]`` table changes.

    Raises:
        ConfigError: A file is missing or not TOML, or a field is missing or wrong; the
            message names the file and the field.
    """
    path = Path(path)
    raw = read_toml(path, "Segway rider gain file")
    changes = raw.get("standing", {})
    if not isinstance(changes, dict):
        raise ConfigError(f"{path}: field 'standing': must be a table")
    base = read_toml(Path(standing), "standing gain file")
    return validate(path, {**raw, "standing": _overlay(base, changes)}, CassieSegwayGains)
