"""``sweep.json``: a sweep's statistics, per controller, per pair of controllers and per
variant, from its rides' summaries (:mod:`ridempc.sweep.stats`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from itertools import combinations
from typing import Any

from ridempc.compare import COMPARED_METRICS
from ridempc.sweep.stats import mcnemar_p, metric_spread, paired_counts, survived, wilson

__all__ = ["SWEEP_METRICS", "VariantRecord", "sweep_results"]

# Metrics summarised per controller: compare's table, when the rider fell [s], and how long
# the backup held the start before the MPC took over [s] (ridempc.mpc.readiness).
SWEEP_METRICS: dict[str, str] = {**COMPARED_METRICS, "fall_time_s": "s", "mpc_takeover_s": "s"}

VariantRecord = Mapping[str, Any]  # id, seed, drawn, scenario_file


def sweep_results(
    header: Mapping[str, Any],
    variants: Sequence[VariantRecord],
    controllers: Sequence[str],
    summaries: Mapping[tuple[str, str], Mapping[str, Any]],
) -> dict[str, Any]:
    """The content of ``sweep.json``.

    Args:
        header: What the sweep was (robot, board, scenario, distribution, seed, ...).
        variants: Each variant's ``id``, ``seed``, ``drawn`` quantities and ``scenario_file``.
        controllers: The controllers, in the order given.
        summaries: Every ride's summary by ``(variant id, controller)``.

    Returns:
        ``controllers``: per controller ``rides``, ``survived``, ``failed``,
        ``fallback_rides`` and ``fallbacks`` (rides handed to a backup law, and handovers
        in all: a summary's ``fallbacks``, :mod:`ridempc.mpc.handover`),
        ``backup_survivals`` (rides that survived on the backup: their last handover never
        handed back, so the ride's end was the backup's, not the controller's), ``survival_rate``,
        ``survival_ci95`` (Wilson, [low, high]), ``metrics`` (median, p90, min, max per
        metric) and ``worker_peak_rss_mib``; ``paired``: per pair of
        controllers the four paired counts and the exact McNemar p-value; ``failed``: the
        failed rides; ``variants``: per variant its drawn quantities and each controller's
        summary.
    """
    outcomes: dict[str, list[bool]] = {c: [] for c in controllers}
    per_controller: dict[str, Any] = {}
    for controller in controllers:
        rides = [summaries[(v["id"], controller)] for v in variants]
        outcomes[controller] = [survived(s) for s in rides]
        kept = sum(outcomes[controller])
        low, high = wilson(kept, len(rides))
        memory = [s["worker_peak_rss_mib"] for s in rides if "worker_peak_rss_mib" in s]
        handovers = [len(s.get("fallbacks") or ()) for s in rides]
        per_controller[controller] = {
            "rides": len(rides),
            "survived": kept,
            "failed": sum(1 for s in rides if s.get("status") == "failed"),
            "fallback_rides": sum(1 for n in handovers if n),
            "fallbacks": sum(handovers),
            "backup_survivals": sum(1 for s in rides if survived(s) and _on_backup(s)),
            "survival_rate": kept / len(rides) if rides else None,
            "survival_ci95": [low, high],
            "metrics": {
                name: {**metric_spread([s.get(name) for s in rides]), "unit": unit}
                for name, unit in SWEEP_METRICS.items()
            },
            "worker_peak_rss_mib": max(memory) if memory else None,
        }
    paired = []
    for a, b in combinations(controllers, 2):
        counts = paired_counts(a, b, outcomes)
        p = mcnemar_p(counts[f"only_{a}_survived"], counts[f"only_{b}_survived"])
        paired.append({"controllers": [a, b], **counts, "mcnemar_p": p})
    return {
        **header,
        "samples": len(variants),
        "failed": sum(c["failed"] for c in per_controller.values()),
        "controllers": per_controller,
        "paired": paired,
        "variants": [
            {**v, "summaries": {c: summaries[(v["id"], c)] for c in controllers}} for v in variants
        ],
    }


def _on_backup(summary: Mapping[str, Any]) -> bool:
    """The ride ended on the backup: its last handover has no ``duration_s`` (never handed
    back, :class:`ridempc.mpc.handover.Fallback`)."""
    fallbacks: Sequence[Mapping[str, Any]] = summary.get("fallbacks") or []
    return bool(fallbacks) and fallbacks[-1].get("duration_s") is None
