"""A law by which a sweep draws one quantity: fixed, uniform, clipped normal or a choice.

A bare number in a distribution file is ``fixed``; :data:`Quantity` is a law field that takes
either, and :func:`within` bounds every value a law can draw.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import AfterValidator, BeforeValidator, Field, model_validator

from ridempc.units import CheckedModel, Real

__all__ = ["Law", "Quantity", "within"]

_LAWS = ("fixed", "uniform", "normal", "choice")


class Law(CheckedModel):
    """How one quantity is drawn: exactly one of the fields below (a bare number in a file
    is ``fixed``).

    Attributes:
        fixed: The value itself.
        uniform: ``[low, high]``, drawn uniformly, ``low < high``.
        normal: ``[mean, std]``, ``std > 0``, clipped to ``clip``.
        clip: ``[low, high]`` for ``normal`` (required: a physical quantity is bounded).
        choice: Values, one drawn with equal probability.
    """

    fixed: Real | None = None
    uniform: tuple[Real, Real] | None = None
    normal: tuple[Real, Real] | None = None
    clip: tuple[Real, Real] | None = None
    choice: tuple[Real, ...] | None = Field(None, min_length=1)

    @model_validator(mode="after")
    def _one_law(self) -> Law:
        given = [law for law in _LAWS if getattr(self, law) is not None]
        if len(given) != 1:
            raise ValueError(
                "allowed: a number, or exactly one of uniform = [low, high], "
                "normal = [mean, std] with clip = [low, high], choice = [a, b, ...]"
                + (f"; got {' and '.join(given)}" if given else "")
            )
        if self.uniform is not None and not self.uniform[0] < self.uniform[1]:
            raise ValueError(
                f"uniform = [{self.uniform[0]:g}, {self.uniform[1]:g}] is empty or inverted; "
                "allowed: [low, high] with low < high"
            )
        if (self.clip is not None) != (self.normal is not None):
            raise ValueError("clip = [low, high] goes with normal, and normal needs it")
        if self.normal is not None and self.clip is not None:
            mean, std = self.normal
            low, high = self.clip
            if not std > 0.0:
                raise ValueError(f"normal std = {std:g}; allowed: above 0")
            if not low < high or not low <= mean <= high:
                raise ValueError(
                    f"clip = [{low:g}, {high:g}] with mean {mean:g}; allowed: low < high "
                    "and the mean between them"
                )
        return self

    @property
    def random(self) -> bool:
        """Whether it varies from variant to variant."""
        return self.fixed is None and not (self.choice is not None and len(set(self.choice)) < 2)

    def bounds(self) -> tuple[float, float]:
        """The lowest and highest value it can draw."""
        if self.fixed is not None:
            return self.fixed, self.fixed
        if self.uniform is not None:
            return self.uniform
        if self.clip is not None:
            return self.clip
        assert self.choice is not None
        return min(self.choice), max(self.choice)

    def draw(self, rng: np.random.Generator) -> float:
        """One value (a fixed one takes nothing from ``rng``)."""
        if self.fixed is not None:
            return float(self.fixed)
        if self.uniform is not None:
            return float(rng.uniform(*self.uniform))
        if self.normal is not None and self.clip is not None:
            return float(np.clip(rng.normal(*self.normal), *self.clip))
        assert self.choice is not None
        return float(self.choice[int(rng.integers(len(self.choice)))])


def _number_is_fixed(value: Any) -> Any:
    return value if isinstance(value, dict) else {"fixed": value}


def within(low: float, high: float, unit: str, low_open: bool = False) -> AfterValidator:
    """A law whose every draw lies in ``[low, high]`` (``(low, high]`` with ``low_open``)."""

    def check(law: Law) -> Law:
        lo, hi = law.bounds()
        if not ((lo > low if low_open else lo >= low) and hi <= high):
            allowed = f"{'(' if low_open else '['}{low:g}, {high:g}]{unit and ' ' + unit}"
            raise ValueError(f"draws in [{lo:g}, {hi:g}]; allowed: within {allowed}")
        return law

    return AfterValidator(check)


Quantity = Annotated[Law, BeforeValidator(_number_is_fixed)]
