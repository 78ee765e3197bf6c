"""The handover triggers: why the MPC cannot ride this tick, in the order they are asked.

After each tick's whole-body QP the rider gathers a :class:`HandoverCheck` and asks each
:class:`HandoverTrigger` of its list in turn; the first reason hands the ride to the
backup law (:mod:`~ridempc.mpc.handover`):

1. :func:`plan_failed`: the MPC's QP failed (its previous plan shifted by one step is used);
2. :class:`DropWatch`: every foot's load gone at once, a step down (:mod:`~ridempc.mpc.drop`;
   with the ``drop`` stage);
3. :func:`needs_slack`: the whole-body QP took slack on its soft rows (:mod:`ridempc.wbc.elastic`);
4. :class:`PushWatch`: a push from outside beyond the pair's impulse band
   (:mod:`~ridempc.mpc.impulse`; with the ``impulse`` stage);
5. :class:`Deviated`: the state beyond the pair's ``[mpc] handover_deviation`` (default
   :data:`~ridempc.mpc.handover.HANDOVER_DEVIATION`) of
   its reference (a re-push's stroke rides out, :mod:`~ridempc.mpc.push_handover`);
6. :func:`diverging`: or heading beyond :data:`~ridempc.mpc.handover.LEAD_DEVIATION` within a
   divergence time, until the MPC has held the rider settled (:mod:`~ridempc.mpc.divergence`).
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np

from ridempc.mpc.bounce import BounceRise
from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.drop import DropDetector
from ridempc.mpc.handover import HANDOVER_DEVIATION, LEAD_DEVIATION
from ridempc.mpc.impulse import ImpulseObserver, ImpulseTrigger
from ridempc.mpc.plan import Plan
from ridempc.mpc.stages.base import ControlTick, present
from ridempc.pair_description import ImpulseStage

__all__ = [
    "DropWatch",
    "HandoverCheck",
    "HandoverTrigger",
    "PushWatch",
    "Deviated",
    "deviated",
    "diverging",
    "handover_triggers",
    "needs_slack",
    "plan_failed",
]


class HandoverCheck(NamedTuple):
    """What the triggers read after a tick's whole-body QP: the plan in force, the QP's
    slack, the state's deviation from its reference [-], whether a re-push's stroke defers
    it, whether the MPC has proven itself since the start or its return, and the
    deviation's divergence."""

    plan: Plan
    slack: float
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


def needs_slack(check: HandoverCheck) -> str | None:
    """The whole-body QP had no solution as posed."""
    slack = check.slack
    return f"whole-body QP infeasible (slack {slack:.3g})" if slack > 0.0 else None


class Deviated:
    """The state beyond ``bound`` [-] of its reference, in its tolerances (unless a
    re-push's stroke defers it); the pair's ``[mpc] handover_deviation``."""

    def __init__(self, bound: float = HANDOVER_DEVIATION) -> None:
        self.bound = bound

    def __call__(self, check: HandoverCheck) -> str | None:
        if check.deviation > self.bound and not check.stroke:
            return f"state {check.deviation:.2g} of its tolerances from the reference"
        return None


deviated = Deviated()  # at the default bound, :data:`~ridempc.mpc.handover.HANDOVER_DEVIATION`


def diverging(check: HandoverCheck) -> str | None:
    """The state heading beyond the lead's bound (:data:`~ridempc.mpc.handover.LEAD_DEVIATION`)
    within a divergence time, while the MPC is on probation."""
    if not check.proven and check.divergence.value > LEAD_DEVIATION:
        return (
            f"state {check.deviation:.2g} of its tolerances from the reference, "
            f"growing at {check.divergence.rate:.2g}/s"
        )
    return None


class DropWatch:
    """The platforms falling away under every foot at once (a step down), from each tick's
    loads (:class:`~ridempc.mpc.drop.DropDetector`): a tick observer and a trigger. The
    rider counts as rising on a bounce's way down until she sinks faster than she rose
    (:class:`~ridempc.mpc.bounce.BounceRise`): its unloaded top is no drop."""

    def __init__(self, detector: DropDetector) -> None:
        self.detector, self.dropping = detector, False
        self.bounce = BounceRise()

    def reset(self) -> None:
        """Start over (a new ride)."""
        self.detector.reset()
        self.bounce.reset()

    def observe(self, tick: ControlTick) -> None:
        estimate = tick.estimate
        rising = self.bounce.update(float(estimate.base_velocity[2]))
        feet = estimate.foot_velocity[:, 2]
        self.dropping = self.detector.update(tick.loads, rising, float(feet.max()))

    def __call__(self, check: HandoverCheck) -> str | None:
        return "every foot's load gone at once (a drop)" if self.dropping else None


class PushWatch:
    """The push from outside, read after each whole-body QP from its centre-of-mass
    velocity and contact forces (:class:`~ridempc.mpc.impulse.ImpulseObserver`): a tick
    observer (of ``wbc_observers``) and a trigger; the observer's window restarts while the
    backup rides (its forces are not the QP's).

    Args:
        observer: The impulse observer.
        trigger: The pair's impulse band.
        divergence_blend: Whether its handover is blended over the rider's divergence time
            (:func:`~ridempc.mpc.push_handover.push_blend`).
    """

    def __init__(
        self, observer: ImpulseObserver, trigger: ImpulseTrigger, divergence_blend: bool = False
    ) -> None:
        self.observer, self._trigger = observer, trigger
        self.divergence_blend = divergence_blend
        self.reason: str | None = None

    @classmethod
    def of(cls, stage: ImpulseStage | None, mass: float) -> PushWatch | None:
        """With the pair's ``impulse`` stage (its bands), the watch of a rider of ``mass``
        [kg], as modelled; None without it."""
        if stage is None:
            return None
        trigger = ImpulseTrigger(stage.band, stage.sideways)
        return cls(ImpulseObserver(mass), trigger, stage.divergence_blend)

    def observe(self, tick: ControlTick) -> None:
        if tick.on_backup:
            self.observer.reset()
            self.reason = None
            return
        out = tick.wbc
        assert out is not None  # after the whole-body QP
        impulse = self.observer.update(tick.sensors.time, out.com_velocity, out.forces.sum(axis=0))
        tick.diagnostics["impulse"] = float(np.hypot(impulse[0], impulse[1]))
        estimate = tick.estimate
        heading = estimate.boards[0].yaw if estimate.boards else estimate.yaw
        self.reason = self._trigger(impulse, heading)

    def __call__(self, check: HandoverCheck) -> str | None:
        """Why the push is beyond what the MPC rides, or None."""
        return self.reason

    def handed(self, failure: str | None) -> bool:
        """Whether ``failure`` (a tick's first reason) is this watch's push, to be blended
        over the rider's divergence time."""
        return self.divergence_blend and failure is not None and failure is self.reason


def handover_triggers(
    drop: DropWatch | None,
    push: PushWatch | None,
    flight: HandoverTrigger | None = None,
    failures_only: bool = False,
    deviation_bound: float = HANDOVER_DEVIATION,
) -> tuple[HandoverTrigger, ...]:
    """The triggers in the order asked (the first reason is the one recorded), with the
    pair's watches where it has them; a drop's flight (:mod:`~ridempc.mpc.flight`) in the
    drop's place, which it rides. ``failures_only``: only what leaves the MPC without a
    command it can trust (1-3: a failed plan, a drop, a whole-body QP on slack), so a ride
    measures the MPC itself (the ``mpc-alone`` ablation), no push or deviation handed over."""
    if failures_only:
        return present(plan_failed, flight or drop, needs_slack)
    far = Deviated(deviation_bound)
    return present(plan_failed, flight or drop, needs_slack, push, far, diverging)
