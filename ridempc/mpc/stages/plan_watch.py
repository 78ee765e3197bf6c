"""The handover's watch over the plans taken up (:class:`PlanWatch`), an observer of the plans.

At each plan's take-up, the MPC's deviation from its reference
(:func:`~ridempc.mpc.handover.deviation`) tells the handover (:mod:`~ridempc.mpc.handover`)
where the rider is heading (:class:`~ridempc.mpc.divergence.DivergentDeviation`), whether
the MPC has shown its model holds her (:class:`~ridempc.mpc.divergence.Probation`), whether
a ride started on the backup may be taken over (:mod:`~ridempc.mpc.readiness`), and how
often the backup must run in standby to take a handover with the state of its own ride
(:func:`~ridempc.mpc.handover.standby_every`).
"""

from __future__ import annotations

from ridempc.mpc.divergence import DivergentDeviation, Probation
from ridempc.mpc.handover import RETURN_DEVIATION, RETURN_DWELL_S, Handover, standby_every
from ridempc.mpc.payload import PayloadEstimator
from ridempc.mpc.readiness import StartReadiness
from ridempc.mpc.stages.build import Built

__all__ = ["STANDBY_WARMUP_S", "PlanWatch"]

# [s] how long from the ride's start the backup's standby runs every tick while the MPC is
# on probation: an unknown model (a payload's offset) tips the rider within 0.5-1 s of the
# start, where the backup's filters are still settling from rest; later its 33 Hz standby
# keeps them current (every tick throughout cost 8 % of the loop's speed).
STANDBY_WARMUP_S: float = 1.0


class PlanWatch:
    """The handover's bookkeeping at each plan's take-up.

    Args:
        handover: The handover to the backup law.
        readiness: The start's readiness (None: the ride starts on the MPC).
        payload: The payload's estimator, whose settling the readiness waits for (or None).
        standby_every: The backup's standby divider [ticks] once warm and settled.
    """

    def __init__(
        self,
        handover: Handover,
        readiness: StartReadiness | None,
        payload: PayloadEstimator | None,
        standby_every: int,
    ) -> None:
        self.handover = handover
        self.readiness = readiness
        self.payload = payload
        self.standby_every = standby_every
        self.divergence = DivergentDeviation()  # where the deviation is heading
        self.probation = Probation()  # whether the MPC has shown its model holds the rider

    def observe(self, time: float, built: Built, com_height: float, commanded: bool) -> None:
        """The plan ``built`` from the state at ``time`` [s] taken up, the centre of mass
        ``com_height`` [m] over the feet, ``commanded`` whether the manoeuvre asks for more
        than balancing (a hold or a stop the backup rides too)."""
        plan = built.plan
        riding = not self.handover.on_backup  # the peak is the MPC's own rides'
        self.divergence.update(time, built.deviation, com_height, riding)
        self.divergence.expect(built.expected)
        if riding:
            settled = not plan.fallback and built.deviation <= RETURN_DEVIATION
            self.probation.update(time, settled, RETURN_DWELL_S)
        else:
            self.probation.restart()
        if self.readiness is not None and self.handover.starting:
            in_band = not plan.fallback and built.deviation <= RETURN_DEVIATION
            settling = self.payload.estimate.settling() if self.payload is not None else None
            self.readiness.update(time, settling, in_band, commanded)
        warming = not self.probation.proven and time < STANDBY_WARMUP_S
        in_return_band = max(built.deviation, self.divergence.value) <= RETURN_DEVIATION
        self.handover.standby_every = standby_every(self.standby_every, warming, in_return_band)
