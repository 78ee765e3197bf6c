"""``ridempc bench``'s tick figures and its profile: keys present and consistent on a very
short ride (no timing is asserted; the figures are a command's, ``ridempc bench``)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

from ridempc.bench import BUDGET_PARTS, TICK_KINDS, bench
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
    assert {"warmup", "mpc_build"} <= set(row["profile_by_tick"]) <= set(TICK_KINDS)
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


def test_a_tick_is_counted_in_its_kind_and_a_wrapped_call_in_its_own() -> None:
    profiler = PartProfiler(("outer", "inner"), ("plain", "busy", "call"))
    inner = profiler.wrap(_busy, "inner")
    called = profiler.wrap_kind(profiler.wrap(_busy, "inner"), "call")
    profiler.start()
    for tick in range(12):
        profiler.begin_tick("busy" if tick % 3 == 0 else "plain")
        if tick % 3 == 0:
            inner()
            called()
        time.sleep(0)
    profiler.stop()
    by_kind = profiler.hottest_by_kind(top=20)
    assert set(by_kind) == {"plain", "busy", "call"}
    assert any("_busy" in f["function"] and f["calls"] == 4 for f in by_kind["busy"])
    assert any("_busy" in f["function"] and f["calls"] == 4 for f in by_kind["call"])
    assert not any("_busy" in f["function"] for f in by_kind["plain"])
    # the loop's own part (the first) is not the controller's: no sleep in any kind
    assert not any("sleep" in f["function"] for fs in by_kind.values() for f in fs)
    # summed over the kinds, the parts see every call
    assert any("_busy" in f["function"] and f["calls"] == 8 for f in profiler.hottest(12)["inner"])
    with pytest.raises(ValueError, match="unknown kind 'other'"):
        profiler.begin_tick("other")
