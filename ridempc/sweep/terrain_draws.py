"""Terrain drawn for each variant of a sweep: the ``[terrain]`` table of a distribution.

At most one terrain item per variant, ahead of the start along :math:`+x`: with
``probability`` a slope or a step (one of ``kinds``, equally likely), else level ground.
Angles and heights are signed: positive up, negative down along :math:`+x`. Example::

    [terrain]
    probability = 0.8                        # [-] of a terrain item at all
    kinds = ["slope", "step"]                # one drawn, equally likely
    start = {uniform = [1.0, 2.0]}           # [m] along x: the slope's foot, the step's edge
    slope_deg = {uniform = [-5.0, 5.0]}      # [deg] with kind "slope"
    slope_length = 2.0                       # [m] horizontal run
    step_height_radii = {uniform = [-0.6, -0.1]}   # [wheel radii] or step_height [m]

Every quantity is drawn for every variant, whatever the kind and the presence drawn, so the
generator's state after them does not depend on the outcome. A variant's ``drawn`` names
``terrain.slope_deg`` and ``terrain.step_height`` (or ``terrain.step_height_radii``) as
ridden, 0 where the variant has no such item, and ``terrain.start`` where it varies.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from ridempc.scenarios.terrain import START_CLEARANCE, WORLD_FRONT
from ridempc.sim.terrain import STEP_DOWN_RADII, STEP_UP_RADII
from ridempc.sweep.laws import Law, Quantity, within
from ridempc.units import CheckedModel, Real

__all__ = ["CHOICES", "TerrainDraws"]

# The draws that choose the item (whether there is one, which kind): drawn for every variant
# but not named in its ``drawn``, which says what it rides (an angle, a height, 0 for none).
CHOICES: tuple[str, ...] = ("terrain.present", "terrain.kind")
# Below a tenth of a degree a slope is level ground for every board: no item is laid.
MIN_SLOPE_DEG: float = 0.1
# Below a millimetre (or a hundredth of a wheel radius) a step is a seam in the floor.
MIN_STEP_M: float = 1e-3
MIN_STEP_RADII: float = 0.01

Start = Annotated[Quantity, within(START_CLEARANCE, WORLD_FRONT, "m")]
# The scenarios' own bound on a slope (30 deg), either way.
SlopeDeg = Annotated[Quantity, within(-30.0, 30.0, "deg")]
SlopeLength = Annotated[Quantity, within(0.0, WORLD_FRONT, "m", low_open=True)]
# The scenarios' own bounds on a step: 1 m, 10 wheel radii, either way.
StepMetres = Annotated[Quantity, within(-1.0, 1.0, "m")]
StepRadii = Annotated[Quantity, within(-10.0, 10.0, "wheel radii")]


class TerrainDraws(CheckedModel):
    """A slope or a step drawn ahead of the start (module docstring).

    Attributes:
        probability: Of a terrain item at all [-].
        kinds: Which items, one drawn with equal probability.
        start: The slope's foot or the step's edge along x [m].
        slope_deg: The slope's angle, positive up [deg] (with ``slope`` among ``kinds``).
        slope_length: The slope's horizontal run [m].
        step_height: The step's height, positive up [m], or None.
        step_height_radii: The step's height, positive up [wheel radii], or None.
    """

    probability: Annotated[Real, Field(ge=0.0, le=1.0)] = 1.0
    kinds: tuple[Literal["slope", "step"], ...] = Field(min_length=1)
    start: Start
    slope_deg: SlopeDeg | None = None
    slope_length: SlopeLength = Law(fixed=3.0)  # the library's slopes run 3 m
    step_height: StepMetres | None = None
    step_height_radii: StepRadii | None = None

    @model_validator(mode="after")
    def _laws_for_the_kinds(self) -> TerrainDraws:
        if len(set(self.kinds)) != len(self.kinds):
            raise ValueError(f"kinds = {list(self.kinds)} names one twice; allowed: each once")
        steps = [f for f in ("step_height", "step_height_radii") if getattr(self, f) is not None]
        if ("slope" in self.kinds) != (self.slope_deg is not None):
            raise ValueError(
                "slope_deg is given exactly when kinds has 'slope'; "
                f"kinds = {list(self.kinds)}, slope_deg {'given' if self.slope_deg else 'missing'}"
            )
        if "step" in self.kinds and len(steps) != 1:
            raise ValueError(
                "kind 'step' takes exactly one of step_height [m] or step_height_radii "
                f"[wheel radii]; got {' and '.join(steps) or 'neither'}"
            )
        if "step" not in self.kinds and steps:
            raise ValueError(f"{steps[0]} is given but kinds = {list(self.kinds)} has no 'step'")
        return self

    @property
    def step_field(self) -> str:
        """``step_height`` or ``step_height_radii``: the one given."""
        return "step_height" if self.step_height is not None else "step_height_radii"

    def quantities(self) -> dict[str, Law]:
        """The laws by dotted name, in drawing order (every one drawn for every variant)."""
        present, kind = CHOICES
        laws = {
            present: Law(uniform=(0.0, 1.0)),
            kind: Law(choice=tuple(float(k) for k in range(len(self.kinds)))),
            "terrain.start": self.start,
        }
        if self.slope_deg is not None:
            laws |= {"terrain.slope_deg": self.slope_deg, "terrain.slope_length": self.slope_length}
        step = self.step_height if self.step_height is not None else self.step_height_radii
        if step is not None:
            laws[f"terrain.{self.step_field}"] = step
        return laws

    def _kind(self, values: Mapping[str, float]) -> str | None:
        """The item a variant rides, or None: level ground (absent, or too small to lay)."""
        if not values["terrain.present"] < self.probability:
            return None
        kind = self.kinds[int(values["terrain.kind"])]
        if kind == "slope":
            return kind if abs(values["terrain.slope_deg"]) >= MIN_SLOPE_DEG else None
        least = MIN_STEP_M if self.step_field == "step_height" else MIN_STEP_RADII
        return kind if abs(values[f"terrain.{self.step_field}"]) >= least else None

    def items(self, values: Mapping[str, float]) -> list[dict[str, Any]]:
        """The variant's ``[[terrain]]`` tables (none or one) from its drawn values."""
        kind = self._kind(values)
        start = values["terrain.start"]
        if kind == "slope":
            angle = values["terrain.slope_deg"]
            return [
                {
                    "kind": "slope",
                    "start": start,
                    "length": values["terrain.slope_length"],
                    "angle": abs(angle),
                    "direction": "up" if angle > 0.0 else "down",
                }
            ]
        if kind == "step":
            height = values[f"terrain.{self.step_field}"]
            return [
                {
                    "kind": "step",
                    "at": start,
                    self.step_field.removeprefix("step_"): abs(height),
                    "direction": "up" if height > 0.0 else "down",
                }
            ]
        return []

    def drawn(self, values: Mapping[str, float]) -> dict[str, float]:
        """What a variant rides, by dotted name: signed angle and height, 0 where absent."""
        kind = self._kind(values)
        out = {"terrain.start": values["terrain.start"]} if self.start.random else {}
        if self.slope_deg is not None:
            out["terrain.slope_deg"] = values["terrain.slope_deg"] if kind == "slope" else 0.0
        if "step" in self.kinds:
            name = f"terrain.{self.step_field}"
            out[name] = values[name] if kind == "step" else 0.0
        return out

    def step_error(self, wheel_radius: float | None, board: str) -> str | None:
        """Why a drawn step is one the board cannot roll (the scene's own limits), or None."""
        if "step" not in self.kinds:
            return None
        law = self.step_height if self.step_height is not None else self.step_height_radii
        assert law is not None
        radii = self.step_field == "step_height_radii"
        if wheel_radius is None:  # no board: nothing rolls, a height in metres only
            return (
                f"field 'terrain.step_height_radii': board '{board}' has no wheels; "
                "allowed: step_height [m]"
                if radii
                else None
            )
        scale = 1.0 if radii else wheel_radius
        unit = "wheel radii" if radii else "m"
        lowest, highest = -STEP_DOWN_RADII * scale, STEP_UP_RADII * scale
        low, high = law.bounds()
        for end, way in ((low, "down"), (high, "up")):
            if not lowest <= end <= highest:
                return (
                    f"field 'terrain.{self.step_field}': draws {end:g} {unit}, a step {way} "
                    f"higher than board '{board}' can roll {way}; allowed: within "
                    f"[{lowest:.4g}, {highest:.4g}] {unit}"
                )
        return None
