"""Where the controller tick's tail comes from: its ticks sorted by their place in the MPC's
period (``ridempc bench``).

Three pieces of work come once per MPC period of :data:`~ridempc.mpc.rider.MPC_DIVIDER`
control ticks, each on a tick of its own: the MPC's tick (phase 0: the estimate mapped and
the problem built and solved, or sent to the solver process or thread), the plan's take-up
(phase ``plan_latency``: reading the plan, waiting for it if it is not done) and the
backup's standby update (phase ``standby_phase``, :mod:`ridempc.mpc.stagger`). They are 3 of
15 ticks, 20 %, so the controller tick's p99 is always one of theirs: it measures the
periodic work, not the tick. :func:`tick_phases` gives each phase's median and the p99 of
the other, *steady* ticks (the estimator, the WBC and the rider's every-tick work), after
the ride's first ``warmup`` seconds, where the standby runs every tick.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["tick_phases"]


def tick_phases(
    seconds: Sequence[float] | NDArray[Any],
    period: int,
    periodic: dict[str, int | None],
    rate_hz: float,
    warmup: float,
) -> dict[str, float]:
    """The controller ticks' times by phase of the MPC period (module docstring).

    Args:
        seconds: Each control tick's time [s] (wall or CPU), from the ride's first.
        period: Control ticks per MPC period.
        periodic: Phase of each periodic piece of work (``mpc_tick``, ``take_up``,
            ``standby``), None where it has no tick of its own.
        rate_hz: Control rate [Hz].
        warmup: Seconds at the ride's start left out [s].

    Returns:
        [ms] ``phase_<k>_median`` for each phase ``k`` of the period, ``<name>_median``
        for each piece of work in ``periodic`` (NaN without a tick of its own),
        ``steady_median`` and ``steady_p99``; NaN where the ride is too short to have them.
    """
    times = 1e3 * np.asarray(seconds, dtype=float)
    ticks = np.arange(times.size)
    kept = ticks >= round(warmup * rate_hz)
    phase = ticks % period
    out: dict[str, float] = {}
    for k in range(period):
        chosen = times[kept & (phase == k)]
        out[f"phase_{k}_median"] = float(np.median(chosen)) if chosen.size else float("nan")
    for name, at in periodic.items():
        out[f"{name}_median"] = out[f"phase_{at}_median"] if at is not None else float("nan")
    busy = [k for k in periodic.values() if k is not None]
    steady = times[kept & ~np.isin(phase, busy)]
    out["steady_median"] = float(np.median(steady)) if steady.size else float("nan")
    out["steady_p99"] = float(np.percentile(steady, 99)) if steady.size else float("nan")
    return out
