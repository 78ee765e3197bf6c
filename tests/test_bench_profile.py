"""``ridempc bench``'s tick figures and its profile: keys present and consistent on a very
short ride (no timing is asserted; the figures are a command's, ``ridempc bench``)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from ridempc.bench import BUDGET_PARTS, bench
from ridempc.tickprofile import PartProfiler


def test_the_json_holds_the_tick_figures_and_the_profile(tmp_path: Path) -> None:
    path = tmp_path / "bench.json"
    bench(["cassie-segway"], seconds=0.1, json_path=path, profile=True)
    row = json.loads(path.read_text())["cassie-segway"]
    for key in (
        "controller_tick_p99_ms",
        "mpc_tick_p99_ms",
        "controller_physics_ratio",
        "reference_ms",
    ):
        assert isinstance(row[key], float) and row[key] > 0.0, key
    assert {"mpc_tick_median", "take_up_median", "standby_median", "steady_p99"} <= set(
        row["tick_phases_ms"]
    )
    assert set(row["profile"]) == set(BUDGET_PARTS)
    for part, functions in row["profile"].items():
        assert functions, part
        shares = [f["share"] for f in functions]
        assert shares == sorted(shares, reverse=True) and sum(shares) <= 1.0 + 1e-9
        assert all(f["calls"] > 0 and f["own_ms_per_tick"] >= 0.0 for f in functions)
    # the estimator's own functions are counted in the estimator, not in the rest
    estimator = " ".join(f["function"] for f in row["profile"]["estimator"])
    assert "estimation/" in estimator


def _busy() -> float:
    return sum(float(i) for i in range(200))


def test_a_call_is_counted_in_the_part_that_made_it() -> None:
    profiler = PartProfiler(("outer", "inner"))
    inner = profiler.wrap(_busy, "inner")
    profiler.start()
    for _ in range(20):
        inner()
        time.sleep(0)
    profiler.stop()
    inner()  # after the stop: not recorded
    hottest = profiler.hottest(ticks=20, top=20)
    assert any("_busy" in f["function"] and f["calls"] == 20 for f in hottest["inner"])
    assert not any("_busy" in f["function"] for f in hottest["outer"])
    assert any("sleep" in f["function"] for f in hottest["outer"])
    with pytest.raises(ValueError, match="unknown part 'other'"):
        profiler.wrap(_busy, "other")
