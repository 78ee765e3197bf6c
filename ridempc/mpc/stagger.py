"""Which tick of the MPC's period each periodic job of the rider takes.

The rider's control loop runs at 500 Hz; three pieces of its work come once per MPC period
of :math:`N` ticks (:data:`~ridempc.mpc.rider.MPC_DIVIDER`): the MPC's tick itself (tick
:math:`0` of the period: the estimate mapped and the problem's inputs sent, or the whole
build and solve at a ``plan_latency`` of 0), the plan taken up ``plan_latency`` ticks later
(:math:`L`), and the backup law's standby update (:mod:`~ridempc.mpc.handover`). Each costs
a large share of a tick, so two of them on one tick would set the controller tick's p99:
the standby takes the tick half a period after the MPC's, :math:`\\lfloor N/2 \\rfloor`, furthest
from the MPC's own, or the next one where the plan is taken up there.
"""

from __future__ import annotations

__all__ = ["standby_phase"]


def standby_phase(period: int, plan_latency: int) -> int:
    """The tick of each period of ``period`` ticks on which the backup's standby runs.

    Args:
        period: The MPC's period [ticks], which the standby shares.
        plan_latency: Ticks from the MPC's tick to the tick its plan is taken up [ticks].

    Returns:
        The tick in ``[1, period)``, neither the MPC's (0) nor the plan's (``plan_latency``).

    Raises:
        ValueError: A period below 3 (no tick free of both) or a latency outside it.
    """
    if period < 3 or not 0 <= plan_latency < period:
        raise ValueError(
            f"period {period}, plan_latency {plan_latency}: allowed a period of 3 ticks or "
            "more and a latency from 0 to the period less one"
        )
    phase = period // 2
    return phase + 1 if phase == plan_latency else phase
