"""``ridempc compare``: two controllers, same scenario and seeds, one table."""

from __future__ import annotations

import json

import pytest

from ridempc.cli import main


def test_compares_two_controllers_over_seeds(tmp_path, capsys) -> None:
    out = tmp_path / "cmp"
    args = ["compare", "--robot", "cyberdog2", "--board", "none", "--scenario", "stand-still"]
    code = main([*args, "--controllers", "stand,pd", "--seeds", "2", "--duration", "0.5",
                 "--out", str(out)])  # fmt: skip
    assert code == 0
    printed = capsys.readouterr().out
    assert "| survived | 2/2 | 2/2 |" in printed
    result = json.loads((out / "comparison.json").read_text())
    assert result["seeds"] == 2 and set(result["controllers"]) == {"stand", "pd"}
    for row in result["controllers"].values():
        assert row["survived"] == 2
        assert row["metrics"]["velocity_rmse"] is not None
        assert row["timings"]["controller_update_ms"]["p99"] > 0.0
    for controller in ("stand", "pd"):
        for seed in (0, 1):
            summary = json.loads((out / controller / f"seed-{seed}" / "summary.json").read_text())
            assert summary["seed"] == seed and summary["controller"] == controller
    assert (out / "overlay.png").stat().st_size > 0
    assert (out / "comparison.md").read_text().startswith("# cyberdog2 / none / stand-still")


def test_bad_input_is_refused_before_anything_runs(tmp_path, capsys) -> None:
    args = ["compare", "--robot", "cyberdog2", "--board", "none", "--scenario", "stand-still"]
    with pytest.raises(SystemExit) as exited:
        main([*args, "--seeds", "0", "--out", str(tmp_path / "a")])
    assert exited.value.code == 2
    assert "--seeds: 0 is out of range" in capsys.readouterr().err
    assert main([*args, "--controllers", "pd", "--out", str(tmp_path / "b")]) == 2
    assert "two different controllers" in capsys.readouterr().err
    assert main([*args, "--controllers", "pd,nope", "--out", str(tmp_path / "c")]) == 2
    assert "nope" in capsys.readouterr().err
    assert not (tmp_path / "c").exists()
