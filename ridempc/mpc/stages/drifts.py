"""The disturbance observers whose estimates the MPC's rates carry as drifts
(:class:`~ridempc.mpc.stages.base.DriftSource`), besides the deck's torque
(:class:`~ridempc.mpc.stages.deck_roll.RollDrift`) and the payload
(:class:`~ridempc.mpc.stages.payload_models.PayloadModels`).

- :class:`SteadyDrift`: the model's steady error on its velocity rows, offset-free MPC
  (:mod:`~ridempc.mpc.disturbance`);
- :class:`LeanDrift`: the centrifugal pull of the frame's turn on the leaning rider
  (:mod:`~ridempc.mpc.lean`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.disturbance import DisturbanceObserver, disturbance_rows
from ridempc.mpc.lean import LeanSteering
from ridempc.mpc.pairs import MpcPair
from ridempc.mpc.stages.base import MpcTick

__all__ = ["LeanDrift", "SteadyDrift", "disturbance_observer"]

Array = NDArray[np.float64]


def disturbance_observer(pair: MpcPair, names: tuple[str, ...]) -> DisturbanceObserver | None:
    """With the pair's ``disturbance`` stage, the observer of the model's steady error on
    its velocity rows (:mod:`~ridempc.mpc.disturbance`) for the MPC's states ``names``."""
    stage = pair.description.stages.disturbance
    if stage is None:
        return None
    rows, angular = disturbance_rows(names, pair.board_states, stage.rows)
    planar = (names.index("vx"), names.index("vy")) if "vx" in names else None
    return DisturbanceObserver(
        rows, angular, stage.time_constant, stage.max_linear, stage.max_angular, planar
    )


class SteadyDrift:
    """The disturbance estimated from the last plan's prediction of ``x0``, as a drift of
    the MPC's rates: estimated while balancing (holding or coasting), held through a
    manoeuvre (its accelerations are not a constant disturbance: estimated through speed
    changes the Hovershoes fell) and while the plan is not followed (the backup rides, or
    a solve is under way).

    Args:
        observer: The disturbance observer.
        dt: The MPC's step [s].
    """

    def __init__(self, observer: DisturbanceObserver, dt: float) -> None:
        self.observer, self._dt = observer, dt

    def drift(self, tick: MpcTick, x0: Array) -> Array | None:
        observer = self.observer
        elapsed = tick.now - tick.plan_time
        hold = tick.held or not tick.balancing
        observer.update(x0, tick.plan, tick.now, elapsed, self._dt, tick.frame_turn, hold)
        tick.diagnostics["disturbance_max"] = float(np.max(np.abs(observer.estimate), initial=0))
        return observer.drift(len(x0))


class LeanDrift:
    """The lean loop's centrifugal drift on the lateral rate (row ``vy``), at the board's
    speed and the estimated yaw rate; its offset in the diagnostics."""

    def __init__(self, lean: LeanSteering, vy: int) -> None:
        self.lean, self._vy = lean, vy

    def drift(self, tick: MpcTick, x0: Array) -> Array | None:
        lean = self.lean
        yaw_rate = tick.estimate.yaw_rate
        centrifugal = lean.drift(len(x0), self._vy, tick.speed, yaw_rate)
        tick.diagnostics["lean_offset"] = lean.offset
        return centrifugal
