"""An integrating estimate of the torque on the skateboard's deck that the MPC's model misses.

The MPC predicts the deck's roll from eqs. (6)-(7),
:math:`I_{Bx}\\ddot\\varphi = \\tau(x, u) - K_B\\varphi - B_B\\dot\\varphi`, with the rider's
roll torque :math:`\\tau` taken from the plan's foot forces about the deck's estimated top
centre (the centroid of the feet standing on it). That torque is biased and mis-scaled in
closed loop, and the plans, which always expect the deck to settle where the model puts it,
never correct what it gets wrong: the plans meet the commanded roll at the horizon's end and
the deck lags it, with a bias after a push-off. The deck itself follows eq. (6)-(7) under
the true foot torque, but the true torque is not the model's: after a push-off the feet
stand off the deck's centre line (the pushing foot lands elsewhere than it lifted), which
the estimate, taking their centroid for the deck's centre, cannot see; and the estimated
centre-of-mass offset from the deck, :math:`\\hat c_y - \\hat o_y`, is smaller than the
true one, while the sway's lateral force, acting below the centre of mass, adds to the
torque per metre of offset (the diagnosis, measured: ``docs/tuning.md``).

As in offset-free MPC, a disturbance torque :math:`d` [N m] is added to the deck's roll
row, held over the horizon, and integrated from the error of the last plan's prediction
of the roll at this tick:

.. math::

    I_{Bx}\\ddot\\varphi = \\tau(x, u) - K_B\\varphi - B_B\\dot\\varphi + d, \\qquad
    d_{j+1} = d_j + \\beta K_B (\\hat\\varphi_j - \\varphi^{pred}_j)

with :math:`\\hat\\varphi_j` the estimated roll at MPC tick :math:`j` and
:math:`\\varphi^{pred}_j` the previous plan's roll at that time (interpolated between its
first two nodes, as the whole-body controller follows it). :math:`K_B` turns a roll error
into the torque that holds it, and :math:`\\beta` [-] is the share of it taken per tick.
On the free deck one tick's roll goes 0.18 of the way to a torque's balance, so each
tick closes :math:`0.18\\beta` of the estimate's error: a time constant of 0.55 s at
:math:`\\beta` = 0.3 (0.32 s at 0.5). The estimate is kept only in four-leg balancing
(before a push-off and while coasting), where all four feet stand on the deck and the
model's contact set is the deck's; it restarts from zero when a push-off ends.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.skateboard.parameters import SkateboardReducedParameters
from ridempc.mpc.plan import Plan

__all__ = ["RollObserver"]

Array = NDArray[np.float64]


@dataclass
class RollObserver:
    """The deck's disturbance torque :math:`d` (module docstring).

    Attributes:
        roll: Index of the deck roll :math:`\\varphi` [rad] in the MPC's state.
        rate: Index of the deck roll rate :math:`\\dot\\varphi` [rad/s].
        deck: The board's identified roll model (:math:`I_{Bx}`, :math:`K_B`).
        gain: :math:`\\beta`, the share of the roll error's holding torque taken per MPC
            tick [-].
        torque: The estimate :math:`d` [N m].
    """

    roll: int
    rate: int
    deck: SkateboardReducedParameters
    gain: float
    torque: float = 0.0
    _running: bool = field(default=False, repr=False)

    def __post_init__(self) -> None:
        if not 0.0 < self.gain <= 1.0:
            raise ValueError(f"RollObserver: gain must be in (0, 1], got {self.gain}")

    def reset(self) -> None:
        """Forget the estimate (a push-off, where the model's contacts are not the deck's)."""
        self.torque, self._running = 0.0, False

    def update(self, x0: Array, plan: Plan | None, share: float, hold: bool = False) -> float:
        """Integrate the roll's prediction error at this tick.

        Args:
            x0: The estimated state at this MPC tick.
            plan: The last plan, solved with the estimate in force then (None: none yet).
            share: How far this tick lies between the plan's first two nodes, in steps [-].
            hold: Keep the estimate as it is (the roll estimate is not to be trusted).

        Returns:
            The updated :math:`d` [N m].
        """
        if plan is not None and self._running and not hold:
            predicted = plan.first_step_state(share)[self.roll]
            self.torque += self.gain * self.deck.roll_stiffness * (x0[self.roll] - predicted)
        self._running = True
        return self.torque

    def drift(self, nx: int) -> Array:
        """The estimate as a constant term of the model's rates :math:`\\dot x` (nx): on the
        roll rate's row, :math:`d / I_{Bx}` [rad/s^2]."""
        out = np.zeros(nx)
        out[self.rate] = self.torque / self.deck.roll_inertia
        return out
