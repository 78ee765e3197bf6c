"""Survival statistics of a sweep: Wilson intervals, paired counts, metric percentiles.

A ride *survived* when it ended without a fall and without a failure; a failed ride (the
ride raised, or its worker died every time it was tried) counts as not survived, and is
counted separately as ``failed``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = [
    "WALL_CLOCK_KEYS",
    "Z95",
    "deterministic",
    "mcnemar_p",
    "metric_spread",
    "paired_counts",
    "survived",
    "wilson",
]

# The normal quantile of a two-sided 95 % interval: Phi^-1(0.975).
Z95: float = 1.959963984540054
# Summary entries that depend on the wall clock or the worker, not on the ride: left out
# when two sweeps' summaries are compared (the rest is bit-identical for the same seeds).
WALL_CLOCK_KEYS: tuple[str, ...] = ("wall_time_s", "real_time_factor", "worker_peak_rss_mib")


def survived(summary: Mapping[str, Any]) -> bool:
    """Whether a ride ended without a fall or a failure."""
    return summary.get("status") == "ok" and not summary.get("fell")


def wilson(successes: int, trials: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion.

    :math:`\\frac{\\hat p + z^2/2n \\pm z\\sqrt{\\hat p(1-\\hat p)/n + z^2/4n^2}}{1 + z^2/n}`,
    which, unlike the normal approximation, stays inside [0, 1] and is not empty at 0 or n
    successes (Wilson 1927; Brown, Cai and DasGupta 2001).

    Args:
        successes: Rides survived.
        trials: Rides (0 gives the uninformative [0, 1]).
        z: Normal quantile of the confidence level (1.96 for 95 %).

    Returns:
        (low, high), each in [0, 1].
    """
    if trials == 0:
        return 0.0, 1.0
    p = successes / trials
    denominator = 1.0 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denominator
    half = z * math.sqrt(p * (1.0 - p) / trials + z * z / (4 * trials * trials)) / denominator
    return max(0.0, centre - half), min(1.0, centre + half)


def paired_counts(a: str, b: str, outcomes: Mapping[str, Sequence[bool]]) -> dict[str, int]:
    """Counts of the four outcomes of two controllers over the same variants.

    Args:
        a: First controller.
        b: Second controller.
        outcomes: Survival per controller, one entry per variant, in variant order.

    Returns:
        ``both_survived``, ``only_<a>_survived``, ``only_<b>_survived``, ``neither_survived``.
    """
    pairs = list(zip(outcomes[a], outcomes[b], strict=True))
    return {
        "both_survived": sum(1 for x, y in pairs if x and y),
        f"only_{a}_survived": sum(1 for x, y in pairs if x and not y),
        f"only_{b}_survived": sum(1 for x, y in pairs if y and not x),
        "neither_survived": sum(1 for x, y in pairs if not (x or y)),
    }


def mcnemar_p(only_a: int, only_b: int) -> float:
    """Exact two-sided McNemar p-value: whether the discordant variants (one controller
    survived, the other fell) split other than evenly, by a binomial test with p = 1/2."""
    n = only_a + only_b
    if n == 0:
        return 1.0
    k = min(only_a, only_b)
    tail = sum(math.comb(n, i) for i in range(k + 1)) / 2.0**n
    return min(1.0, 2.0 * tail)


def metric_spread(values: Sequence[float | None]) -> dict[str, float | int | None]:
    """Median, 90th percentile, minimum and maximum of a metric over rides (None when no
    ride reported it), and the number of rides that did."""
    finite = [float(v) for v in values if v is not None and math.isfinite(float(v))]
    if not finite:
        return {"median": None, "p90": None, "min": None, "max": None, "rides": 0}
    array = np.asarray(finite)
    return {
        "median": float(np.median(array)),
        "p90": float(np.percentile(array, 90.0)),
        "min": float(array.min()),
        "max": float(array.max()),
        "rides": len(finite),
    }


def deterministic(summary: Mapping[str, Any]) -> dict[str, Any]:
    """A summary without what depends on the wall clock or the worker
    (:data:`WALL_CLOCK_KEYS`, and every timing ``*_ms``): what two sweeps of the same
    variants and seeds must agree on bit for bit."""
    return {k: v for k, v in summary.items() if k not in WALL_CLOCK_KEYS and not k.endswith("_ms")}
