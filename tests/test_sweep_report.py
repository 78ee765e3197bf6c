"""sweep.json's figures and the report, from made-up summaries (no ride)."""

from __future__ import annotations

from pathlib import Path

import pytest

from ridempc.sweep.aggregate import sweep_results
from ridempc.sweep.report import write_report

HEADER = {"robot": "cassie", "board": "hovershoes", "scenario": "stand-still",
          "distribution": "everyday", "seed": 0, "duration": None}  # fmt: skip


def _results(
    pd_falls: set[int], mpc_falls: set[int], n: int = 10, handed: frozenset[int] = frozenset()
) -> dict:
    variants = [
        {"id": f"v{i:04d}", "seed": 100 + i, "drawn": {"push.magnitude": 0.1 * i},
         "scenario_file": f"variants/v{i:04d}.toml"}
        for i in range(n)
    ]  # fmt: skip
    summaries = {}
    for c, falls in (("pd", pd_falls), ("mpc", mpc_falls)):
        for i, v in enumerate(variants):
            fell = i in falls
            summaries[(v["id"], c)] = {
                "controller": c, "seed": v["seed"], "status": "ok", "fell": fell,
                "fall_time_s": 2.0 + i if fell else None, "velocity_rmse": 0.01 * (i + 1),
                "worker_peak_rss_mib": 300.0,
            }  # fmt: skip
            if c == "mpc" and i in handed:  # handed to the PD once, or twice for i = 3
                fallback = {"time_s": 1.0, "reason": "WbcFailed: ...", "duration_s": 0.6}
                kept = {**fallback, "duration_s": None}  # i = 1: the PD rides to the end
                last = kept if i == 1 else fallback
                summaries[(v["id"], c)]["fallbacks"] = [fallback] * (1 if i == 3 else 0) + [last]
    return sweep_results(HEADER, variants, ["pd", "mpc"], summaries)


@pytest.mark.parametrize(("pd_falls", "mpc_falls"), [(set(), set()), (set(range(10)), {1, 2})])
def test_report_at_the_extremes(tmp_path: Path, pd_falls, mpc_falls) -> None:
    results = _results(pd_falls, mpc_falls)
    write_report(results, tmp_path)  # every or no ride survived: intervals touch 0 or 1
    assert (tmp_path / "report.html").read_text().count("data:image/png;base64,") == 3
    assert "ridempc sim --robot cassie" in (tmp_path / "report.md").read_text()


def test_sweep_results_counts() -> None:
    results = _results({7, 8, 9}, {8, 9, 0})
    pd, mpc = results["controllers"]["pd"], results["controllers"]["mpc"]
    assert (pd["survived"], mpc["survived"], pd["rides"]) == (7, 7, 10)
    assert pd["survival_ci95"] == pytest.approx([0.3968, 0.8922], abs=1e-4)
    assert results["paired"] == [{
        "controllers": ["pd", "mpc"], "both_survived": 6, "only_pd_survived": 1,
        "only_mpc_survived": 1, "neither_survived": 2, "mcnemar_p": 1.0,
    }]  # fmt: skip
    assert pd["metrics"]["velocity_rmse"]["median"] == pytest.approx(0.055)
    assert pd["metrics"]["fall_time_s"]["rides"] == 3 and pd["worker_peak_rss_mib"] == 300.0
    assert results["failed"] == 0 and len(results["variants"]) == 10


def test_worst_rides_name_the_draws_furthest_in_the_tails() -> None:
    from ridempc.sweep.report import EXTREME_DRAWS, _extreme_draws

    variants = [
        {"id": f"v{i}", "drawn": {"a": float(i), "b": float(-i), "c": 1.0, "d": float(i % 5),
                                  "e": float(i * i % 7)}}
        for i in range(10)
    ]  # fmt: skip
    named = _extreme_draws(variants)
    assert all(len(names) == EXTREME_DRAWS for names in named.values())
    assert set(named["v9"][:2]) == {"a 9 (top 5 %)", "b -9 (bottom 5 %)"}  # the extremes
    assert not any(name.startswith("c ") for names in named.values() for name in names)


def test_fallbacks_are_counted_and_reported(tmp_path: Path) -> None:
    results = _results(set(), {8}, handed=frozenset({1, 3, 8}))
    mpc = results["controllers"]["mpc"]
    assert (mpc["fallback_rides"], mpc["fallbacks"]) == (3, 4)
    assert mpc["backup_survivals"] == 1  # v0001 ended on the PD; v0003 handed back twice
    assert results["controllers"]["pd"]["fallbacks"] == 0
    write_report(results, tmp_path)
    assert "| mpc | 9/10 | 90.0% |" in (tmp_path / "report.md").read_text()
    assert "3 rides (4), 1 survived on it" in (tmp_path / "report.md").read_text()
