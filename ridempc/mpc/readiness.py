"""When the MPC has earned the ride from the backup balance it starts on.

At a ride's start the MPC's model is the nominal rider: a payload (up to a third of the
rider's mass) or a moved centre of mass is unknown to it until its estimators
(:mod:`ridempc.mpc.payload`) have read the stance's loads for a while, and a linear MPC
on a wrong mass or centre of mass tips its rider within the balance's first divergence
times (0.3 s for a 0.9 m centre of mass). The backup (the pair's PD balance,
:mod:`ridempc.mpc.handover`) needs no model, so the ride starts on it, the MPC planning
beside it from the current state and its estimators learning from the PD's stance, and
the MPC takes the ride when

- its model's estimates have *settled*: over the last :attr:`StartRule.window` [s] each
  estimate :math:`e_j` moved by no more than its tolerance,
  :math:`\\max_w e_j - \\min_w e_j \\le \\epsilon_j`, with a full window of readings; and
- the rider is within the MPC's return band of its reference (its deviation within
  :data:`~ridempc.mpc.handover.RETURN_DEVIATION`, the MPC's plan solved) for
  :attr:`StartRule.dwell` [s], as a return from any handover asks; the reference's frame
  is laid on the board while the backup holds it (the backup balances, it does not hold a
  place or a heading: the MPC takes over where the rider is). The deviation's divergent
  lead (:mod:`ridempc.mpc.divergence`) is left out here: it is the growth beyond what the
  MPC's plan expected, and the backup does not follow that plan (under the PD it swung
  between 0.6 and 2.7 and kept a settled rider out of the band);

or, regardless of both,

- a manoeuvre is commanded that only the MPC rides (anything but balancing in place or
  the stop that rides out a push: the backup holds the rider, it does not follow the
  library), at once (taken over at a push's stop, the MPC was handed back 0.03 s later:
  hard seed 31, v0018);

or, regardless of the estimates,

- the rule has waited :attr:`StartRule.longest_wait` [s] and the rider is in the band
  for the dwell: estimates that never settle (a noisy load signal) do not keep the ride
  on the backup for good. The band is not waived: taken over at the longest wait
  whatever the band, with estimates still moving, the MPC fell within 0.3-0.6 s where the
  PD stood (hard, seed 31: three of the first nine variants).

The MPC takes the ride only where it has a command and no failure (the handover's own
check). While it waits, the summary says for what (:meth:`StartReadiness.summary`).

The estimates watched are the ones that learn while the backup rides: the payload's,
read from the stance's loads, there the running mean of the readings so far
(:mod:`ridempc.mpc.payload`). Its steps shrink as :math:`1/k`, so a window whose spread is
within the tolerances is a mean that has stopped moving, near the truth; a slow low pass
would pass the same test long before it had taken up its offset (its 2 s integration read
settled at 0.5 s with half a centimetre of a 0.94 cm offset still to come).

The disturbance observer (:mod:`ridempc.mpc.disturbance`) learns from the MPC's own
plan's prediction error, which the backup does not follow: it is held until the MPC rides,
and its probation (:mod:`ridempc.mpc.divergence`) covers it.

Each outcome is recorded with its reason (:meth:`StartReadiness.summary`).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ridempc.pair_description import TakeoverStage

__all__ = [
    "LONGEST_WAIT",
    "MANOEUVRE",
    "SETTLED",
    "StartReadiness",
    "StartRule",
    "start_readiness",
]

Array = NDArray[np.float64]
# the reasons the MPC takes over
SETTLED = "estimates settled and the rider in the return band"
MANOEUVRE = "a manoeuvre commanded"
LONGEST_WAIT = "the longest wait"
# [s] times within this are equal: a tick's time carries the rounding of its sum
TIME_TOLERANCE: float = 1e-9


@dataclass(frozen=True)
class StartRule:
    """The takeover's parameters (a pair's ``[stages.takeover]``).

    Attributes:
        window: The time over which each estimate's change is measured [s].
        tolerances: Each estimate's largest change over the window (its units).
        dwell: How long the rider must stay in the return band [s].
        longest_wait: When the MPC takes over whatever its estimates [s].
        by_prediction: Whether, once it rides, the MPC is proven only by its plans'
            one-step predictions holding as well as its state near its reference
            (:meth:`~ridempc.mpc.divergence.DivergentDeviation.settled`): a model that
            had to earn the ride keeps it on the same proof.
    """

    window: float
    tolerances: tuple[float, ...]
    dwell: float
    longest_wait: float
    by_prediction: bool = False


class StartReadiness:
    """Whether the MPC may take the ride from the backup it started on, MPC tick by tick.

    Args:
        rule: The takeover's parameters.

    Attributes:
        ready: Whether it may, from the last :meth:`update` on (it stays so).
        reason: Why it may (:data:`SETTLED`, :data:`MANOEUVRE`, :data:`LONGEST_WAIT`).
        ready_s: When it became ready [s].
    """

    def __init__(self, rule: StartRule) -> None:
        self.rule = rule
        self.ready = False
        self.reason: str | None = None
        self.ready_s: float | None = None
        self._start: float | None = None
        self._history: deque[tuple[float, Array]] = deque()
        self._since: float | None = None  # [s] the first reading of the window's run
        self._band_since: float | None = None
        self.spread: Array = np.full(len(rule.tolerances), np.inf)
        self._waiting = "the first plan"  # what it waits for, while it waits

    def update(self, time: float, estimates: Array | None, in_band: bool, manoeuvre: bool) -> bool:
        """Whether ready at ``time`` [s], with the model's ``estimates`` now (one per
        tolerance; None or empty where the pair estimates nothing), the rider ``in_band``,
        and a ``manoeuvre`` commanded."""
        if self.ready:
            return True
        self._start = time if self._start is None else self._start
        settled = self._settled(time, estimates)
        if not in_band:
            self._band_since = None
        elif self._band_since is None:
            self._band_since = time
        dwelt = self._band_since is not None and (
            time - self._band_since >= self.rule.dwell - TIME_TOLERANCE
        )
        self._waiting = "the estimates to settle" if not settled else "the return band"
        if manoeuvre:
            return self._become(time, MANOEUVRE)
        if settled and dwelt:
            return self._become(time, SETTLED)
        waited = time - self._start >= self.rule.longest_wait - TIME_TOLERANCE
        if waited and dwelt:
            return self._become(time, LONGEST_WAIT)
        return False

    def _settled(self, time: float, estimates: Array | None) -> bool:
        """Whether every estimate moved within its tolerance over a full window."""
        if estimates is None or len(estimates) == 0:
            return True
        values = np.asarray(estimates, dtype=float)
        if len(values) != len(self.rule.tolerances) or not np.isfinite(values).all():
            self._history.clear()  # a NaN restarts the window
            self._since = None
            return False
        history = self._history
        history.append((time, values))
        self._since = time if self._since is None else self._since
        while history and time - history[0][0] > self.rule.window + TIME_TOLERANCE:
            history.popleft()
        stacked = np.array([v for _, v in history])
        self.spread = stacked.max(axis=0) - stacked.min(axis=0)
        full = time - self._since >= self.rule.window - TIME_TOLERANCE
        return full and bool(np.all(self.spread <= np.asarray(self.rule.tolerances)))

    def _become(self, time: float, reason: str) -> bool:
        self.ready, self.reason, self.ready_s = True, reason, time
        return True

    def summary(self) -> dict[str, Any]:
        """For ``summary.json``: when the MPC was ready and why; never ready, the reason
        None and what it still waited for."""
        out: dict[str, Any] = {"ready_s": self.ready_s, "reason": self.reason}
        if not self.ready:
            out["waiting_for"] = self._waiting
        return out


def start_readiness(stage: TakeoverStage | None, dwell: float) -> StartReadiness | None:
    """The readiness of a pair's ``[stages.takeover]`` (None: the MPC rides from its first
    plan), its estimates the payload's :meth:`~ridempc.mpc.payload.PayloadEstimate.settling`
    (mass fraction, offset along and across) and ``dwell`` [s] in the return band."""
    if stage is None:
        return None
    tolerances = (stage.mass_change, stage.shift_change, stage.shift_change)
    rule = StartRule(stage.window, tolerances, dwell, stage.longest_wait, stage.by_prediction)
    return StartReadiness(rule)
