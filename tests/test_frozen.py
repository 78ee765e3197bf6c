"""A frozen dataclass with fields changed: the same object as ``dataclasses.replace`` makes,
whichever way it is made, and ``replace`` itself wherever ``__init__`` does more than store."""

from __future__ import annotations

import dataclasses
from dataclasses import InitVar, dataclass, field
from functools import cached_property

import numpy as np
import pytest

from ridempc.estimation.state import BoardEstimate
from ridempc.frozen import changed
from ridempc.robots.motor_curve import TorqueSpeedCurve


@dataclass(frozen=True)
class Plain:
    a: float
    b: np.ndarray
    c: tuple[str, ...] = ()

    @cached_property
    def doubled(self) -> np.ndarray:
        return 2.0 * self.b


@dataclass(frozen=True)
class Derived:
    a: float
    twice: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "twice", 2.0 * self.a)


@dataclass(frozen=True)
class WithInitVar:
    a: float
    scale: InitVar[float] = 10.0

    def __post_init__(self, scale: float) -> None:
        object.__setattr__(self, "a", self.a * scale)


def _same(x: object, y: object) -> bool:
    return type(x) is type(y) and all(
        np.array_equal(getattr(x, f.name), getattr(y, f.name)) for f in dataclasses.fields(x)
    )


def test_a_stored_dataclass_changes_as_replace_would() -> None:
    board = BoardEstimate(("left",), np.zeros(3), 0.1, 0.02, -0.03, np.ones(3), 0.4)
    made = changed(board, yaw=0.25)
    assert _same(made, dataclasses.replace(board, yaw=0.25))
    assert made.yaw == 0.25 and board.yaw == 0.1  # the original is untouched
    with pytest.raises(dataclasses.FrozenInstanceError):
        made.yaw = 0.0  # type: ignore[misc]


def test_a_cached_value_is_not_carried_over() -> None:
    plain = Plain(1.0, np.ones(2))
    assert np.array_equal(plain.doubled, [2.0, 2.0])
    made = changed(plain, b=np.full(2, 3.0))
    assert np.array_equal(made.doubled, [6.0, 6.0])


def test_classes_whose_init_does_more_go_through_replace() -> None:
    assert changed(Derived(1.0), a=3.0).twice == 6.0
    curve = TorqueSpeedCurve(np.array([10.0]), np.array([5.0]), np.array([10.0]))
    doubled = np.array([20.0])
    assert _same(changed(curve, peak=doubled), dataclasses.replace(curve, peak=doubled))
    assert changed(WithInitVar(1.0), a=2.0).a == dataclasses.replace(WithInitVar(1.0), a=2.0).a
    assert changed(WithInitVar(1.0), a=2.0).a == 20.0  # __init__ ran, with the default scale


def test_an_unknown_field_raises_as_replace_does() -> None:
    with pytest.raises(TypeError):
        changed(Plain(1.0, np.ones(2)), d=1.0)
