"""The distributed engine (Dask, ``ridempc[cluster]``) rides exactly what the local pool rides."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ridempc.errors import ConfigError
from ridempc.scenarios import resolve_scenario
from ridempc.sweep import engines
from ridempc.sweep.engines import DaskEngine, LocalEngine, make_engine
from ridempc.sweep.runner import RideTask, run_rides
from ridempc.sweep.stats import deterministic


def _tasks(folder: Path) -> list[RideTask]:
    push = resolve_scenario("push", "hovershoes").with_duration(1.5)
    return [
        RideTask(
            f"v{i:04d}",
            "pd",
            "cassie",
            "hovershoes",
            push,
            seed=i,
            summary_path=folder / f"v{i:04d}.json",
        )  # fmt: skip
        for i in range(2)
    ]


def test_a_dask_cluster_gives_the_local_pools_summaries(tmp_path: Path) -> None:
    pytest.importorskip(
        "dask.distributed",
        reason='the cluster extra is not installed: pip install "ridempc[cluster]"',
    )
    results = {}
    for name in ("local", "dask"):
        engine = make_engine(name, 2, None)
        try:
            results[name] = run_rides(_tasks(tmp_path / name), engine)
        finally:
            engine.close()
    assert isinstance(engine, DaskEngine) and engine.slots == 2
    assert results["local"].keys() == results["dask"].keys()
    for key, local in results["local"].items():
        assert local["status"] == "ok" and local["worker_peak_rss_mib"] > 0.0
        assert deterministic(local) == deterministic(results["dask"][key])  # bit for bit


def test_an_engine_that_is_not_installed_is_one_line(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails
    with pytest.raises(ConfigError, match=r'--engine dask: .* pip install "ridempc\[cluster\]"'):
        make_engine("dask", 2, None)


def test_the_local_engine_takes_no_address() -> None:
    with pytest.raises(ConfigError, match="--address tcp://x:1: the local engine has no address"):
        make_engine("local", 2, "tcp://x:1")
    assert isinstance(make_engine("local", 1, None), LocalEngine)


def test_an_unreachable_address_is_one_line(monkeypatch) -> None:
    pytest.importorskip(
        "dask.distributed",
        reason='the cluster extra is not installed: pip install "ridempc[cluster]"',
    )
    monkeypatch.setattr(engines, "CONNECT_TIMEOUT_S", 0.5)  # nothing listens on port 9
    with pytest.raises(ConfigError, match="--address tcp://127.0.0.1:9: no Dask scheduler") as info:
        make_engine("dask", 2, "tcp://127.0.0.1:9")
    assert "\n" not in str(info.value)
