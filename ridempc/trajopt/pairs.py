"""Robot-board pairs the trajectory optimisation knows: those with a pair file.

A pair is a :class:`Pair`: how to turn target values into library entries, how to check a
target before solving, how to build an entry's NLP and its initial guess (cold, or warm from
a neighbouring entry), and the continuous dynamics the stored trajectories follow. It is made
from the pair's file (``pairs/<robot>-<board>.toml``, :mod:`ridempc.pair_description`) by the
builder of the trajectory problem the file names (:data:`PROBLEMS`): a new pair is a new file.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.pair_description import (
    PairDescription,
    load_pair_description,
    pair_description_names,
)
from ridempc.trajopt.problem import TrajectoryProblem

__all__ = ["PROBLEMS", "EntrySpec", "Guess", "Neighbour", "Pair", "load_pair", "pair_names"]

Array = NDArray[np.float64]

# A pair file's ``trajopt.problem`` -> the module whose ``make_pair`` builds its Pair.
PROBLEMS: dict[str, str] = {
    "ride": "ridempc.trajopt.ride_pair",
    "skate": "ridempc.trajopt.skate_pair",
}


@dataclass(frozen=True)
class EntrySpec:
    """One trajectory to optimise.

    Attributes:
        kind: What the trajectory does (``accelerate``, ``stop``, ``turn``).
        target: Its target value (a speed [m/s] for every kind so far).
        options: Overrides of the pair's option fields (e.g. a coarser ``dt`` for a test).
    """

    kind: str
    target: float
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"{self.kind}-{self.target:.2f}"


class Neighbour(NamedTuple):
    """A solved entry used to warm-start another one."""

    name: str
    times: Array
    states: Array
    inputs: Array
    metadata: dict[str, Any]


class Guess(NamedTuple):
    """An initial guess: states (N+1 x nx), inputs (N x nu), midpoints (N x nx) or None."""

    states: Array
    inputs: Array
    midpoints: Array | None


class Pair(NamedTuple):
    """What the library builder needs from a robot-board pair.

    Attributes:
        robot: Robot name.
        board: Board name.
        default_targets: Targets of the committed library.
        entries: Targets -> entry specifications (one or more per target).
        check: Raises ``ConfigError`` for a target the pair cannot reach, before solving.
        build: Builds an entry's NLP.
        guess: Initial guess for a built problem, from a neighbour when one is given.
        rates: Builds the continuous dynamics :math:`f(x, u, p)` of an entry from its stored
            metadata (for checking stored trajectories without building the NLP).
        board_states: Indices of the board's states in the state vector.
    """

    robot: str
    board: str
    default_targets: tuple[float, ...]
    entries: Callable[[Sequence[float]], list[EntrySpec]]
    check: Callable[[EntrySpec], None]
    build: Callable[[EntrySpec], TrajectoryProblem]
    guess: Callable[[TrajectoryProblem, Neighbour | None], Guess]
    rates: Callable[[dict[str, Any]], ca.Function]
    board_states: Callable[[], tuple[int, ...]]

    @property
    def name(self) -> str:
        return f"{self.robot}-{self.board}"


def pair_names() -> tuple[str, ...]:
    """The pairs described in ``pairs/``."""
    return pair_description_names()


@cache
def load_pair(robot: str, board: str) -> Pair:
    """The pair of that robot and board, made from its pair file (once per process).

    Raises:
        UnknownNameError: No pair file for that pair; the message lists the pairs described.
        ConfigError: The pair file is malformed or does not fit its robot and board.
    """
    description = load_pair_description(robot, board)
    module = importlib.import_module(PROBLEMS[description.trajopt.problem])
    make: Callable[[PairDescription], Pair] = module.make_pair
    return make(description)
