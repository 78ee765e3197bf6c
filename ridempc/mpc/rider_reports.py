"""The MPC rider's reports (:class:`RiderReports`, between its parts and its loop): its
estimate, its diagnostics at each tick, and the ride's summary for ``summary.json`` (solve
times, fallbacks, handovers, the safe hold).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ridempc.estimation import EstimatedState
from ridempc.mpc.rider_parts import RiderParts

__all__ = ["RiderReports"]


class RiderReports(RiderParts):
    """What the rider reports of its ride (its parts: :class:`RiderParts`)."""

    def estimate(self) -> EstimatedState | None:
        return self.estimator.state

    def diagnostics(self) -> dict[str, float]:
        return dict(self._diagnostics)

    @property
    def mpc_tick_ms(self) -> tuple[float, ...]:
        """Each MPC tick's time so far [ms]: building the problem and solving it (the
        solve's own time, not the ticks it runs alongside)."""
        return tuple(self.book.ms)

    @property
    def mpc_loop_seconds(self) -> float:
        """The MPC's time in the control loop's thread so far [s]: building, starting and
        finishing its solves, and waiting for one still running when its tick comes."""
        return self._mpc_main_s

    def summary(self) -> dict[str, Any]:
        """Solve times, fallbacks and the safe hold, for ``summary.json``: the MPC's QP
        (``mpc_solve_ms``: its update and OSQP's solve, as ``ridempc bench`` times it) and
        its whole tick (``mpc_tick_ms``: building the problem too), median and p99 [ms]."""
        out: dict[str, Any] = {}
        for key, values in (
            ("mpc_solve_ms", self.book.qp_ms),
            ("mpc_tick_ms", self.book.ms),
            ("wbc_solve_ms", self._wbc_ms),
        ):
            if values:
                ms = np.asarray(values)
                out[key] = {"median": float(np.median(ms)), "p99": float(np.percentile(ms, 99))}
        out["mpc_solves"] = len(self.book.ms)
        out["speed_preview_s"] = self.commands.speed_preview_s()
        out["mpc_fallbacks"] = self.book.failures
        out["wbc_failures"] = self._wbc_failures
        out["wbc_cold_retries"] = self.wbc.qp.cold_retries
        out["wbc_daqp_solves"] = self.wbc.qp.fallbacks
        out["wbc_elastic_solves"] = self.wbc.qp.elastic_solves
        out["wbc_slack_max"] = self._wbc_slack_max
        out["fallbacks"] = self.handover.summary()
        out["mpc_takeover_s"] = 0.0 if self.readiness is None else self.handover.takeover_s
        if self.readiness is not None:
            out["takeover"] = self.readiness.summary()
        out["deviation_divergent_max"] = self.watch.divergence.peak
        out["impulse_max"] = self.impulse.peak if self.impulse is not None else None
        out["impulse_max_time_s"] = self.impulse.peak_time if self.impulse is not None else None
        out["flights_s"] = list(self.flight.starts) if self.flight is not None else None
        out["flight_depths_m"] = list(self.flight.depths) if self.flight is not None else None
        out["safe_hold"] = (
            None
            if self._hold_reason is None
            else {"time_s": self._hold_time, "reason": self._hold_reason}
        )
        return out
