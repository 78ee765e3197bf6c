"""A sweep's statistics: Wilson intervals, paired counts, McNemar, metric spreads."""

from __future__ import annotations

import pytest

from ridempc.sweep.stats import deterministic, mcnemar_p, metric_spread, paired_counts, wilson

# Newcombe (1998), "Two-sided confidence intervals for the single proportion", Statistics in
# Medicine 17, Table I, method 3 (Wilson score, no continuity correction), to 4 decimals.
NEWCOMBE_TABLE = [
    (81, 263, 0.2553, 0.3662),
    (15, 148, 0.0624, 0.1605),
    (0, 20, 0.0000, 0.1611),
    (1, 29, 0.0061, 0.1718),
    (29, 29, 0.8830, 1.0000),
]


@pytest.mark.parametrize(("k", "n", "low", "high"), NEWCOMBE_TABLE)
def test_wilson_matches_the_published_table(k: int, n: int, low: float, high: float) -> None:
    got = wilson(k, n)
    assert got == pytest.approx((low, high), abs=5e-5)


def test_wilson_without_rides_is_uninformative() -> None:
    assert wilson(0, 0) == (0.0, 1.0)


def test_paired_counts_and_mcnemar() -> None:
    outcomes = {
        "pd": [True, True, False, False, True, False],
        "mpc": [True, False, True, False, False, False],
    }
    counts = paired_counts("pd", "mpc", outcomes)
    assert counts == {
        "both_survived": 1,
        "only_pd_survived": 2,
        "only_mpc_survived": 1,
        "neither_survived": 2,
    }
    assert sum(counts.values()) == 6
    assert mcnemar_p(0, 0) == 1.0
    assert mcnemar_p(2, 1) == 1.0  # 3 discordant pairs: nothing to say
    assert mcnemar_p(10, 0) == pytest.approx(2 * 0.5**10)  # exact binomial, two-sided
    assert mcnemar_p(7, 3) == pytest.approx(2 * (1 + 10 + 45 + 120) / 1024)


def test_metric_spread_skips_missing_values() -> None:
    spread = metric_spread([1.0, None, 3.0, 2.0, float("nan")])
    assert spread == {"median": 2.0, "p90": pytest.approx(2.8), "min": 1.0, "max": 3.0, "rides": 3}
    assert metric_spread([None])["median"] is None


def test_deterministic_drops_the_wall_clock() -> None:
    summary = {"fell": False, "wall_time_s": 1.2, "real_time_factor": 2.0,
               "controller_update_ms": {"median": 0.4}, "worker_peak_rss_mib": 300.0}  # fmt: skip
    assert deterministic(summary) == {"fell": False}
