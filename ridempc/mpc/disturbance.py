"""One general disturbance observer over the MPC's reduced-model states (offset-free MPC).

Whatever the reduced model leaves out (a payload's off-centre weight, the board's drag or a
misidentified parameter, the legs' own momentum) shows as a steady error in the accelerations
it predicts. As in offset-free MPC (Pannocchia & Rawlings 2003; Maeder, Borrelli & Morari
2009), the model is augmented with a constant disturbance :math:`d` on its velocity rows
:math:`S` (the rider's centroidal linear and angular velocities, the board's speeds and
rates),

.. math::

    \\dot x = f(x, u, p) + S d, \\qquad \\dot d = 0,

estimated at each MPC tick :math:`j` from the one-step prediction error: the last plan,
solved with :math:`\\hat d_{j-1}` in its rates and followed with its first input, predicted
:math:`x^{pred}_j` a time :math:`h` after the state it started from; the new estimate
:math:`\\hat x_j` differs from it on those rows by :math:`(d - \\hat d_{j-1})\\, h`, so

.. math::

    \\hat d_j = \\hat d_{j-1} + L\\, S^T (\\hat x_j - x^{pred}_j) / h, \\qquad
    L = \\Delta t / \\tau,

a steady Luenberger (the steady Kalman gain of a random-walk disturbance seen through
white measurement noise has this form): each tick of length :math:`\\Delta t` takes the
share :math:`\\Delta t / \\tau` of the measured residual acceleration, a first-order low
pass with the time constant :math:`\\tau` [s] of the pair file's ``[stages.disturbance]``.
:math:`\\tau` lies between the balance's fall time (:math:`\\sqrt{h_c / g}` about 0.3 s for a
0.9 m centre of mass: slower, the rider falls before the estimate has settled) and the
estimate's noise (the velocities' noise over one MPC step, divided by the step, is metres per
second squared: faster, the estimate passes it to the plan). Each row is bounded by the
pair's largest steady disturbance (``max_linear`` [m/s^2] on linear rows, ``max_angular``
[rad/s^2] on angular ones): beyond it is no constant load the rider can stand on, but a fall
or a push, which the estimate must not wind up on.

The plan then counteracts :math:`\\hat d` as an affine drift of the rates over the horizon
(:func:`~ridempc.mpc.problem.linearize`'s ``drift``), which gives offset-free tracking of a
constant disturbance. The planar velocity's prediction is turned by the library frame's
turn since the plan (the frame follows the board: :class:`~ridempc.mpc.state_map.StateMap`),
and the estimate is held while the plan is not what the rider follows (the fallback law
rides) or there is no plan yet.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.canonical import BoardState
from ridempc.mpc.plan import Plan

__all__ = [
    "ANGULAR_ROWS",
    "BOARD_RATES",
    "DisturbanceObserver",
    "GROUPS",
    "HORIZONTAL_ROWS",
    "VERTICAL_ROWS",
    "disturbance_rows",
]

Array = NDArray[np.float64]
# The rider's centroidal velocity rows, by their canonical names in the MPC's state.
HORIZONTAL_ROWS: tuple[str, ...] = ("vx", "vy")
VERTICAL_ROWS: tuple[str, ...] = ("vz",)
ANGULAR_ROWS: tuple[str, ...] = ("wx", "wy", "wz")
# The board's states that are rates of others (canonical quantities), with whether each is
# an angular rate (else a speed [m/s]).
BOARD_RATES: Mapping[str, bool] = {
    "speed": False,
    "pitch_rate": True,
    "roll_rate": True,
    "yaw_rate": True,
}
# The rows a pair may choose: the rider's horizontal and vertical centroidal velocity, its
# angular velocity, the board's rates.
GROUPS: tuple[str, ...] = ("horizontal", "vertical", "angular", "board")


def disturbance_rows(
    state_names: Sequence[str],
    board_states: Mapping[str, BoardState],
    groups: Sequence[str] = GROUPS,
) -> tuple[tuple[int, ...], tuple[bool, ...]]:
    """The velocity rows :math:`S` of a pair's state, and whether each is angular.

    Args:
        state_names: The MPC's state names (canonical rider names ``vx`` ... ``wz``).
        board_states: The board's states by name, with their canonical quantities.
        groups: Which of :data:`GROUPS` to take.

    Raises:
        ValueError: An unknown group.
    """
    unknown = [g for g in groups if g not in GROUPS]
    if unknown:
        raise ValueError(f"unknown disturbance rows '{unknown[0]}' (valid: {', '.join(GROUPS)})")
    names = list(state_names)
    rows: list[tuple[int, bool]] = []
    if "horizontal" in groups:
        rows += [(names.index(n), False) for n in HORIZONTAL_ROWS if n in names]
    if "vertical" in groups:
        rows += [(names.index(n), False) for n in VERTICAL_ROWS if n in names]
    if "angular" in groups:
        rows += [(names.index(n), True) for n in ANGULAR_ROWS if n in names]
    if "board" in groups:
        rows += [
            (names.index(n), BOARD_RATES[s.quantity])
            for n, s in board_states.items()
            if s.quantity in BOARD_RATES and n in names
        ]
    rows.sort()
    return tuple(i for i, _ in rows), tuple(a for _, a in rows)


@dataclass
class DisturbanceObserver:
    """The disturbance :math:`\\hat d` on the velocity rows (module docstring).

    Attributes:
        rows: :math:`S`, the rows' indices in the MPC's state.
        angular: Per row, whether it is an angular rate (its bound ``max_angular``).
        time_constant: :math:`\\tau` [s].
        max_linear: Bound of a linear row's :math:`|\\hat d|` [m/s^2].
        max_angular: Bound of an angular row's :math:`|\\hat d|` [rad/s^2].
        planar: The indices of the planar velocity (vx, vy) turned with the frame, or None.
        estimate: :math:`\\hat d`, per row.
    """

    rows: tuple[int, ...]
    angular: tuple[bool, ...]
    time_constant: float
    max_linear: float
    max_angular: float
    planar: tuple[int, int] | None = None
    estimate: Array = field(default_factory=lambda: np.zeros(0))
    _last: float | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if len(self.rows) != len(self.angular):
            raise ValueError("DisturbanceObserver: one 'angular' flag per row")
        if not self.time_constant > 0.0:
            raise ValueError(
                f"DisturbanceObserver: time_constant must be positive, got {self.time_constant}"
            )
        if not (self.max_linear > 0.0 and self.max_angular > 0.0):
            raise ValueError("DisturbanceObserver: the bounds must be positive")
        self.estimate = np.zeros(len(self.rows))
        self._bound = np.where(self.angular, self.max_angular, self.max_linear)

    def reset(self) -> None:
        """Forget the estimate."""
        self.estimate = np.zeros(len(self.rows))
        self._last = None

    def predicted(self, plan: Plan, elapsed: float, dt: float, turn: float = 0.0) -> Array:
        """The state ``plan`` predicts ``elapsed`` [s] after its first (linear between its
        first two nodes, a step of ``dt`` [s]), its planar velocity turned by ``turn`` [rad]
        into a frame turned that much further (:math:`R_z(-turn)`)."""
        out = plan.first_step_state(elapsed / dt)
        if self.planar is not None and turn != 0.0:
            i, k = self.planar
            c, s = math.cos(turn), math.sin(turn)
            out[i], out[k] = c * out[i] + s * out[k], -s * out[i] + c * out[k]
        return out

    def update(
        self,
        x0: Array,
        plan: Plan | None,
        now: float,
        elapsed: float,
        dt: float,
        turn: float = 0.0,
        hold: bool = False,
    ) -> Array:
        """One MPC tick's update from the prediction error.

        Args:
            x0: The estimated state :math:`\\hat x_j` (nx).
            plan: The last plan, solved with the estimate then in force and followed since
                (None: none yet).
            now: The tick's time [s].
            elapsed: :math:`h`, the time since the state the plan starts from [s].
            dt: The plan's step [s].
            turn: The library frame's turn since the plan's [rad].
            hold: Keep the estimate (the plan is not what the rider follows).

        Returns:
            :math:`\\hat d` per row.
        """
        step = None if self._last is None else now - self._last
        self._last = now
        if plan is None or hold or step is None or not 0.0 < elapsed <= dt:
            return self.estimate
        if not np.all(np.isfinite(x0)):
            return self.estimate
        error = (x0 - self.predicted(plan, elapsed, dt, turn))[list(self.rows)]
        gain = min(1.0, step / self.time_constant)
        estimate = self.estimate + gain * error / elapsed
        self.estimate = np.clip(estimate, -self._bound, self._bound)
        return self.estimate

    def drift(self, nx: int) -> Array:
        """:math:`S \\hat d`, a constant term of the model's rates (nx)."""
        out = np.zeros(nx)
        out[list(self.rows)] = self.estimate
        return out
