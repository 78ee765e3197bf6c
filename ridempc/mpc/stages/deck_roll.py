"""The deck-roll stages of four-leg balancing on a rolling deck (the skateboard).

Two feet on each side of the deck's centre line hold its roll. While the rider balances
(holds before a push-off, or coasts after one) with all four feet on the deck:

- :class:`RollDrift`, a :class:`~ridempc.mpc.stages.base.DriftSource`: the deck's
  disturbance torque that the MPC's model misses (:mod:`~ridempc.mpc.roll_observer`), held,
  not integrated, while the feet of one side are off the deck or both planned at the
  least force: two feet on one fore-aft line do not see the deck's roll, and the estimate
  winds up;
- :class:`StanceRoll`: the commanded deck roll held within what the four feet's estimated
  stance can hold (:mod:`~ridempc.mpc.stance`).

Both restart when the rider stops balancing (a push-off changes the stance).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.boards.canonical import BoardState
from ridempc.estimation import EstimatedState
from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.pairs import MpcPair
from ridempc.mpc.roll_observer import RollObserver
from ridempc.mpc.stages.base import MpcTick
from ridempc.mpc.stance import StanceLimit
from ridempc.trajopt.skateboard import skateboard_model

__all__ = [
    "DeckSides",
    "DeckStages",
    "RollDrift",
    "StanceRoll",
    "deck_stages",
    "side_feet",
    "to_deck",
]

Array = NDArray[np.float64]


def to_deck(yaw: float, planar: Array) -> Array:
    """Horizontal vectors [m] (..., 2), world axes, in the deck's (along, across) axes."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.asarray(planar, dtype=float) @ np.array([[c, -s], [s, c]])


def side_feet(n_feet: int) -> int:
    """Feet per side of the deck for a rider standing on it on two sides of feet (a
    quadruped's two), 0 for one foot a side: the roll observer's and the stance's sides."""
    return n_feet // 2 if n_feet >= 4 and n_feet % 2 == 0 else 0


class DeckSides:
    """The feet on the deck's two sides and the MPC's least force on one.

    Args:
        mpc: The rider's MPC (its reference, which a manoeuvre's change replaces, read at
            each call).
        weight: The robot's weight [N].
        side: Feet per side (:func:`side_feet`; 0: not a two-sided stance).
    """

    def __init__(self, mpc: LinearMpc, weight: float, side: int) -> None:
        self._mpc, self.weight, self.side = mpc, weight, side

    def least_force(self) -> float:
        """The MPC's least force of a foot on the deck [N]."""
        reference = self._mpc.reference
        return reference.min_board_share * self.weight / len(reference.force_index)

    def one_side_light(self, tick: MpcTick) -> bool:
        """Whether both feet of one side (left or right of the deck's centre line, by their
        estimated places) are off the deck or planned within 1 N of the least force."""
        estimate, plan = tick.estimate, tick.plan
        board, side, index = estimate.board, self.side, self._mpc.reference.force_index
        if board is None or plan is None or not side:
            return False
        if len(estimate.foot_position) != 2 * side or len(index) != 2 * side:
            return False
        contact = np.asarray(estimate.contact, dtype=bool)
        light = ~contact | (plan.first_input[index[:, 2]] <= self.least_force() + 1.0)
        across = to_deck(board.yaw, estimate.foot_position[:, :2])[:, 1]
        order = np.argsort(across)
        return bool(light[order[:side]].all() or light[order[side:]].all())


class RollDrift:
    """The deck's estimated disturbance torque as a drift of the MPC's rates, in four-leg
    balancing; None elsewhere (module docstring).

    Args:
        observer: The deck's torque observer.
        sides: The stance's sides.
        dt: The MPC's step [s].
    """

    def __init__(self, observer: RollObserver, sides: DeckSides, dt: float) -> None:
        self.observer, self._sides, self._dt = observer, sides, dt

    def drift(self, tick: MpcTick, x0: Array) -> Array | None:
        observer = self.observer
        if not tick.balancing:
            observer.reset()
            return None
        share = (tick.now - tick.plan_time) / self._dt
        hold = self._sides.one_side_light(tick)
        tick.diagnostics["roll_disturbance"] = observer.update(x0, tick.plan, share, hold)
        return observer.drift(len(x0))


class StanceRoll:
    """The commanded deck roll held within what the stance can hold, in four-leg
    balancing, from the four feet's estimated places (the last bounds while one is off the
    deck); as commanded elsewhere (module docstring).

    Args:
        limit: The stance's limit.
        sides: The stance's sides.
        com: The estimate's centre of mass [m], world frame.
    """

    def __init__(
        self, limit: StanceLimit, sides: DeckSides, com: Callable[[EstimatedState], Array]
    ) -> None:
        self.limit, self._sides, self._com = limit, sides, com

    def __call__(self, roll: Array, tick: MpcTick) -> Array:
        """``roll`` [rad] at the horizon's nodes, held within the stance's bounds."""
        limit, estimate = self.limit, tick.estimate
        board = estimate.board
        if board is None:
            return roll
        if not tick.balancing:
            limit.reset()
            return roll
        side = self._sides.side
        feet = np.asarray(estimate.foot_position, dtype=float)
        four = bool(side) and len(feet) == 2 * side
        if not four or not np.all(estimate.contact) or tick.plan is None:
            return np.clip(roll, *limit.last)
        com = self._com(estimate)
        centre = feet[:, :2].mean(axis=0)
        places = to_deck(board.yaw, feet[:, :2] - centre)
        offset = to_deck(board.yaw, com[:2] - centre)
        far_share = 2.0 * self._sides.least_force() / self._sides.weight
        dt = tick.now - tick.plan_time
        low, high = limit.bounds(places, offset, float(board.roll), dt, far_share)
        tick.diagnostics.update(stance_low=low, stance_high=high)
        return np.clip(roll, low, high)


class DeckStages(NamedTuple):
    """A pair's deck-roll stages: the deck's steering gain :math:`K_{board}` [1/m] where it
    steers by its roll (the ``roll_steering`` stage), the deck's torque as a drift (the
    ``roll_observer`` stage) and the stance's hold on the commanded roll (the ``stance``
    stage, with the observer); None where the pair has not the stage."""

    steer_gain: float | None
    drift: RollDrift | None
    stance: StanceRoll | None


def deck_stages(
    pair: MpcPair,
    board: Board | None,
    columns: Mapping[BoardState, int],
    mpc: LinearMpc,
    n_feet: int,
    com: Callable[[EstimatedState], Array],
) -> DeckStages:
    """The deck-roll stages the pair file names, for ``board`` (its description, or None),
    the MPC's board state ``columns``, its ``n_feet`` feet and the estimate's ``com``."""
    stages = pair.description.stages
    rolls = stages.roll_steering is not None or stages.roll_observer is not None
    deck = skateboard_model(board).reduced if board is not None and rolls else None
    steers = deck if stages.roll_steering is not None else None
    gain = pair.roll_observer
    roll, roll_rate = BoardState(0, "roll"), BoardState(0, "roll_rate")  # the deck's
    observer = (
        RollObserver(columns[roll], columns[roll_rate], deck, gain)
        if deck is not None and gain is not None and roll_rate in columns
        else None
    )
    sides = DeckSides(mpc, pair.weight, side_feet(n_feet))
    limit = (
        StanceLimit(pair.stance_roll)
        if observer is not None and pair.stance_roll is not None
        else None
    )
    return DeckStages(
        steers.steer_gain if steers is not None else None,
        RollDrift(observer, sides, mpc.settings.dt) if observer is not None else None,
        StanceRoll(limit, sides, com) if limit is not None else None,
    )
