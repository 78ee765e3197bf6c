"""The handover triggers: why the MPC cannot ride this tick, in the order they are asked.

After each tick's whole-body QP the rider gathers a :class:`HandoverCheck` and asks each
:class:`HandoverTrigger` of its list in turn; the first reason hands the ride to the
backup law (:mod:`~ridempc.mpc.handover`):

1. :func:`plan_failed`: the MPC's QP failed (its previous plan shifted by one step is used);
2. :func:`dropped`: every foot's load gone at once, a step down (:mod:`~ridempc.mpc.drop`);
3. :func:`needs_slack`: the whole-body QP took slack on its soft rows (:mod:`ridempc.wbc.elastic`);
4. :func:`pushed`: a push from outside beyond the pair's impulse band
   (:class:`PushWatch`, :mod:`~ridempc.mpc.impulse`);
5. :func:`deviated`: the state beyond :data:`~ridempc.mpc.handover.HANDOVER_DEVIATION` of
   its reference (a re-push's stroke rides out, :mod:`~ridempc.mpc.push_handover`);
6. :func:`diverging`: or heading there within a divergence time, until the MPC has held
   the rider settled (:mod:`~ridempc.mpc.divergence`).
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation import EstimatedState
from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.handover import HANDOVER_DEVIATION
from ridempc.mpc.impulse import ImpulseObserver, ImpulseTrigger
from ridempc.mpc.plan import Plan

__all__ = [
    "HANDOVER_TRIGGERS",
    "HandoverCheck",
    "HandoverTrigger",
    "PushWatch",
    "deviated",
    "diverging",
    "dropped",
    "needs_slack",
    "plan_failed",
    "pushed",
]

Array = NDArray[np.float64]


class HandoverCheck(NamedTuple):
    """What the triggers read after a tick's whole-body QP: the plan in force, whether the
    feet's loads dropped, the QP's slack, why a push is beyond the MPC (or None), the
    state's deviation from its reference [-], whether a re-push's stroke defers it, whether
    the MPC has proven itself since the start or its return, and the deviation's
    divergence."""

    plan: Plan
    dropping: bool
    slack: float
    pushed: str | None
    deviation: float
    stroke: bool
    proven: bool
    divergence: DivergentDeviation


class HandoverTrigger(Protocol):
    """Why the MPC cannot ride, from a tick's check, or None if nothing says so."""

    def __call__(self, check: HandoverCheck) -> str | None: ...


def plan_failed(check: HandoverCheck) -> str | None:
    """The MPC's QP failed."""
    return f"MPC plan failed (status {check.plan.status})" if check.plan.fallback else None


def dropped(check: HandoverCheck) -> str | None:
    """The platforms fell away under every foot at once."""
    return "every foot's load gone at once (a drop)" if check.dropping else None


def needs_slack(check: HandoverCheck) -> str | None:
    """The whole-body QP had no solution as posed."""
    slack = check.slack
    return f"whole-body QP infeasible (slack {slack:.3g})" if slack > 0.0 else None


def pushed(check: HandoverCheck) -> str | None:
    """A push beyond what the MPC rides."""
    return check.pushed


def deviated(check: HandoverCheck) -> str | None:
    """The state beyond the handover's bound of its reference (unless a re-push's stroke
    defers it)."""
    if check.deviation > HANDOVER_DEVIATION and not check.stroke:
        return f"state {check.deviation:.2g} of its tolerances from the reference"
    return None


def diverging(check: HandoverCheck) -> str | None:
    """The state heading beyond the handover's bound within a divergence time, while the
    MPC is on probation."""
    if not check.proven and check.divergence.value > HANDOVER_DEVIATION:
        return (
            f"state {check.deviation:.2g} of its tolerances from the reference, "
            f"growing at {check.divergence.rate:.2g}/s"
        )
    return None


# in the order asked: the first reason is the one recorded
HANDOVER_TRIGGERS: tuple[HandoverTrigger, ...] = (
    plan_failed,
    dropped,
    needs_slack,
    pushed,
    deviated,
    diverging,
)


class PushWatch:
    """The push from outside, read every tick from the whole-body QP's centre-of-mass
    velocity and contact forces (:class:`~ridempc.mpc.impulse.ImpulseObserver`); the
    observer's window restarts while the backup rides (its forces are not the QP's).

    Args:
        observer: The impulse observer.
        trigger: The pair's impulse band.
    """

    def __init__(self, observer: ImpulseObserver, trigger: ImpulseTrigger) -> None:
        self.observer, self._trigger = observer, trigger

    def __call__(
        self,
        estimate: EstimatedState,
        now: float,
        on_backup: bool,
        com_velocity: Array,
        contact_force: Array,
        diagnostics: dict[str, float],
    ) -> str | None:
        """Why the push is beyond what the MPC rides, or None."""
        if on_backup:
            self.observer.reset()
            return None
        impulse = self.observer.update(now, com_velocity, contact_force)
        diagnostics["impulse"] = float(np.hypot(impulse[0], impulse[1]))
        heading = estimate.boards[0].yaw if estimate.boards else estimate.yaw
        return self._trigger(impulse, heading)
