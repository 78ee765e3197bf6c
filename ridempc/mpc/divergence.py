"""The divergent component of the MPC's deviation: a handover to the backup in time.

A rider on a board is an inverted pendulum over its support: an error in its lean grows as
:math:`e^{\\omega t}` with :math:`\\omega = \\sqrt{g / h}` [1/s] for a centre of mass
:math:`h` [m] above its feet, and only its *divergent component of motion*
:math:`\\xi = x + \\dot x / \\omega` tells where it is going; the level alone tells only where
it is. The handover (:mod:`~ridempc.mpc.handover`) compared the MPC's deviation
:math:`d` (:func:`~ridempc.mpc.handover.deviation`, its state from its reference in units of
what its weights accept) with :data:`~ridempc.mpc.handover.HANDOVER_DEVIATION`; a rider
toppling crosses it about one divergence time :math:`1/\\omega` (0.3 s for Cassie) before
she is down, too late for the backup to stop a lean it did not start.

Not every growth of :math:`d` is a fall: a new manoeuvre's reference runs ahead of the
rider, and its plan *expects* the deviation to grow before it closes it. What the plan did
not expect is the model failing: the deviation :math:`d_k` measured at an MPC tick against
the deviation :math:`\\hat d_k` of the state the previous tick's plan predicted for it
(its :math:`x_1` from its :math:`x^{ref}_1`),

.. math:: \\dot d_u = (d_k - \\hat d_k) / \\Delta t, \\qquad
          \\xi_d = d + \\max(\\dot d_u, 0) / \\omega

is where the deviation is heading, a divergence time on, beyond what the plan meant; it
crosses the threshold that much earlier in a fall, and a manoeuvre ridden as planned hardly
moves it. Only growth leads (:math:`\\dot d_u > 0`): a rider doing better than planned is
no reason to hand over, and no sooner a reason to hand back.

:math:`\\dot d_u` is low-passed over :data:`RATE_FILTER_S`: one tick's surprise carries the
estimate's noise and the whole-body QP's own tracking error.

The lead applies while the MPC is on :class:`Probation`: from the ride's start and from
each return to it, until it has held the rider settled for a dwell. A surprise after that
is a push from outside (the library's 1 N/kg push on the Segway led the deviation to 3.06),
which the rider rides out; one before it is the model's own (a payload's unknown offset).
"""

from __future__ import annotations

import math

from ridempc.gravity import GRAVITY
from ridempc.mpc.handover import TIME_TOLERANCE

__all__ = ["GRAVITY", "RATE_FILTER_S", "DivergentDeviation", "Probation"]

# [s] the unexpected growth low-passed over a third of a rider's divergence time (Cassie's
# 1/omega = 0.3 s): one MPC step's surprise (1/30 s) carries the estimate's noise
RATE_FILTER_S: float = 0.1


class DivergentDeviation:
    """:math:`\\xi_d = d + \\max(\\dot d_u, 0)/\\omega` of the MPC's deviation, tick by tick.

    Each MPC tick: :meth:`update` with the deviation measured, then :meth:`expect` with the
    one its new plan predicts for the next tick.

    Attributes:
        value: The latest :math:`\\xi_d` [-].
        rate: The latest low-passed :math:`\\dot d_u` [1/s].
        peak: The largest counted :math:`\\xi_d` so far [-].
    """

    def __init__(self, rate_filter_s: float = RATE_FILTER_S) -> None:
        self.rate_filter_s = rate_filter_s
        self.value = 0.0
        self.rate = 0.0
        self.peak = 0.0
        self._time: float | None = None  # [s] the last update's
        self._expected: float | None = None  # [-] the deviation the last plan predicted

    def reset(self) -> None:
        """Forget the rate and the prediction (a new reference: its deviation steps, no
        plan predicted it)."""
        self._time = self._expected = None
        self.rate = 0.0

    def settled(self, bound: float, deviation: float, by_prediction: bool = True) -> bool:
        """Whether :math:`\\xi_d \\le` ``bound`` [-]: the state near its reference *and*
        the plan's one-step prediction of it holding (the model fits the rider), the test
        of :class:`Probation` and of a return; with ``by_prediction`` False, the
        ``deviation`` [-] alone (a pair whose divergence does not settle standing still:
        the Segway's knee bar carries weight the feet's model does not see)."""
        return (self.value if by_prediction else deviation) <= bound

    def expect(self, deviation: float) -> None:
        """The deviation [-] the plan just solved predicts for the next MPC tick."""
        self._expected = deviation

    def update(self, time: float, deviation: float, height: float, counted: bool = True) -> float:
        """:math:`\\xi_d` with the deviation ``deviation`` [-] measured at ``time`` [s] and
        the centre of mass ``height`` [m] above the feet; ``counted``: in :attr:`peak`."""
        if self._time is not None and self._expected is not None and time > self._time:
            step = time - self._time
            raw = (deviation - self._expected) / step
            share = min(1.0, step / self.rate_filter_s) if self.rate_filter_s > 0.0 else 1.0
            self.rate += share * (raw - self.rate)
        self._time, self._expected = time, None
        omega = math.sqrt(GRAVITY / max(height, 1e-3))
        self.value = deviation + max(self.rate, 0.0) / omega
        if counted:
            self.peak = max(self.peak, self.value)
        return self.value


class Probation:
    """Whether the MPC has yet to show that its model holds the rider: from the ride's
    start, and again from each return to it, until it has been fit (its divergent
    deviation within the return band, :data:`~ridempc.mpc.handover.RETURN_DEVIATION`,
    :meth:`DivergentDeviation.settled`) for a dwell. The level alone is not enough: a
    model that is wrong (the board's firmware or tyres off its parameters) holds the state
    within the band for a while, each plan's prediction missed by the same margin, while
    the error it feeds grows; only a prediction that holds shows the model fits.

    The lead of :class:`DivergentDeviation` hands over on the growth a plan did not expect;
    that is the model failing only where nothing else acts on the rider. Once the MPC has
    held her settled, its model holds, and a surprise from then on is a push from outside,
    which the rider rides out (and which the deviation alone still hands over where it
    grows beyond the handover's bound). Before that, as when a payload's unknown offset
    tips her over in the first half second, the surprise is the model's own.

    Attributes:
        proven: Whether the MPC has been fit for the dwell since the last :meth:`restart`.
    """

    def __init__(self) -> None:
        self.proven = False
        self._fit_since: float | None = None

    def restart(self) -> None:
        """On probation again (the MPC takes the ride back from the backup)."""
        self.proven = False
        self._fit_since = None

    def update(self, time: float, fit: bool, dwell: float) -> bool:
        """Whether proven, with the MPC ``fit`` at ``time`` [s] and ``dwell`` [s] the time it
        must stay fit."""
        if self.proven:
            return True
        if not fit:
            self._fit_since = None
            return False
        self._fit_since = time if self._fit_since is None else self._fit_since
        self.proven = time - self._fit_since >= dwell - TIME_TOLERANCE
        return self.proven
