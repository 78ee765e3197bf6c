"""Library storage: round trip, and every kind of corrupt or tampered file refused."""

from __future__ import annotations

import hashlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.library import build as build_module
from ridempc.library.build import build_library
from ridempc.library.store import load_library, read_manifest, store_entry, write_manifest
from ridempc.trajopt.problem import TrajectorySolution

N, NX, NU, NP = 6, 3, 2, 1


def _record(name: str = "accelerate-0.30") -> dict[str, Any]:
    return {
        "name": name,
        "kind": name.split("-")[0],
        "target": float(name.split("-")[1]),
        "status": "Solve_Succeeded",
        "iterations": 12,
        "solve_time_s": 1.5,
        "build_time_s": 2.0,
        "max_violation": 1e-9,
        "n_intervals": N,
        "dt": 0.1,
        "nx": NX,
        "nu": NU,
        "n_parameters": NP,
        "drift": {
            "local": 1e-4,
            "local_board": 1e-5,
            "board": 1e-5,
            "board_final": {"v": 1e-6},
            "open_loop_time": 0.3,
            "integrator": "RK45",
        },
        "warm_start": None,
        "metadata": {"pair": "test"},
    }


def _arrays() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(0)
    return {
        "times": np.arange(N + 1) * 0.1,
        "states": rng.normal(size=(N + 1, NX)),
        "inputs": rng.normal(size=(N, NU)),
        "midpoints": rng.normal(size=(N, NX)),
        "parameters": np.ones((N, NP)),
        "state_names": np.array(["x", "v", "roll"]),
        "input_names": np.array(["f", "g"]),
    }


@pytest.fixture
def library(tmp_path: Path) -> Path:
    records = [
        store_entry(tmp_path, _record(n), _arrays()) for n in ("accelerate-0.30", "accelerate-0.50")
    ]
    write_manifest(tmp_path, "cyberdog2", "skateboard", records)
    return tmp_path


def _rehash(folder: Path, name: str) -> None:
    """Make the manifest's hash match the (changed) file, as a careful forger would."""
    path = folder / "manifest.json"
    manifest = json.loads(path.read_text())
    for entry in manifest["entries"]:
        if entry["name"] == name:
            entry["sha256"] = hashlib.sha256((folder / f"{name}.npz").read_bytes()).hexdigest()
    path.write_text(json.dumps(manifest))


def test_round_trip(library: Path) -> None:
    manifest, entries = load_library(library)
    assert [e.record.name for e in entries] == ["accelerate-0.30", "accelerate-0.50"]
    arrays = _arrays()
    for entry in entries:
        assert np.array_equal(entry.states, arrays["states"])
        assert entry.state_names == ("x", "v", "roll")
        assert np.array_equal(entry.state("v"), arrays["states"][:, 1])
    assert manifest.robot == "cyberdog2"
    assert not list(library.glob(".*.tmp"))  # no temporary files left behind


def test_tampered_file_is_refused(library: Path) -> None:
    path = library / "accelerate-0.30.npz"
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(ConfigError, match=r"accelerate-0\.30\.npz: content hash .* does not match"):
        load_library(library)


def test_missing_entry_file_is_refused(library: Path) -> None:
    (library / "accelerate-0.50.npz").unlink()
    with pytest.raises(ConfigError, match=r"accelerate-0\.50\.npz: entry file not found"):
        load_library(library)


def test_wrong_shape_is_refused_even_with_a_matching_hash(library: Path) -> None:
    arrays = _arrays()
    arrays["states"] = arrays["states"][:-1]
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    (library / "accelerate-0.30.npz").write_bytes(buffer.getvalue())
    _rehash(library, "accelerate-0.30")
    with pytest.raises(ConfigError, match=r"accelerate-0\.30\.npz: array 'states' has shape"):
        load_library(library)


def test_missing_array_is_refused(library: Path) -> None:
    arrays = _arrays()
    del arrays["inputs"]
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    (library / "accelerate-0.30.npz").write_bytes(buffer.getvalue())
    _rehash(library, "accelerate-0.30")
    with pytest.raises(ConfigError, match="array 'inputs' is missing"):
        load_library(library)


def test_pickled_objects_are_never_loaded(library: Path) -> None:
    arrays: dict[str, Any] = _arrays()
    arrays["states"] = np.array([object()] * (N + 1), dtype=object)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)  # pickles the object array
    (library / "accelerate-0.30.npz").write_bytes(buffer.getvalue())
    _rehash(library, "accelerate-0.30")
    with pytest.raises(ConfigError, match="not a readable .npz of plain arrays"):
        load_library(library)
    with pytest.raises(ConfigError, match="Python objects"):
        store_entry(library, _record(), {**_arrays(), "states": arrays["states"]})


def test_non_finite_values_are_refused(library: Path) -> None:
    arrays = _arrays()
    arrays["inputs"][2, 1] = np.nan
    with pytest.raises(ConfigError, match="NaN"):
        store_entry(library, _record(), arrays)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda m: m["entries"][0].pop("sha256"), "field 'entries.0.sha256'"),
        (lambda m: m["entries"][0].update(status="Infeasible_Problem_Detected"), "status"),
        (
            lambda m: m["entries"][0].update(file="../../etc/passwd"),
            "expected 'accelerate-0.30.npz'",
        ),
        (lambda m: m.update(version=7), "field 'version'"),
        (lambda m: m["entries"][0].update(iterations="many"), "iterations"),
        (lambda m: m["entries"][0]["metadata"].update(mass=float("nan")), "holds NaN"),
        (lambda m: m["entries"][0].update(dt=float("inf")), "holds Infinity"),
    ],
)
def test_bad_manifest_fields_are_refused(library: Path, change, message: str) -> None:
    path = library / "manifest.json"
    manifest = json.loads(path.read_text())
    change(manifest)
    path.write_text(json.dumps(manifest))
    with pytest.raises(ConfigError, match=message) as info:
        read_manifest(library)
    assert "manifest.json" in str(info.value)


def test_manifest_that_is_not_json_is_refused(library: Path) -> None:
    (library / "manifest.json").write_text("{ not json")
    with pytest.raises(ConfigError, match="manifest.json: not valid JSON"):
        read_manifest(library)


def test_no_library_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no motion library here"):
        read_manifest(tmp_path)


def test_an_entry_ipopt_fails_is_reported_and_never_written(tmp_path: Path, monkeypatch) -> None:
    """A failed solve leaves no file and no manifest entry (the solver is stubbed)."""

    def failing(problem, states, inputs, midpoints=None, **_: Any) -> TrajectorySolution:
        return TrajectorySolution(
            name=problem.name,
            status="Maximum_Iterations_Exceeded",
            success=False,
            iterations=1000,
            solve_time=1.0,
            build_time=1.0,
            objective=0.0,
            max_violation=1.0,
            states=states,
            inputs=inputs,
            midpoints=states[1:],
            timing={},
        )

    monkeypatch.setattr(build_module, "solve_trajectory", failing)
    report = build_library("cyberdog2", "skateboard", [0.3], out=tmp_path, progress=False)
    assert len(report.failed) == 1
    assert "Maximum_Iterations_Exceeded" in (report.failed[0].error or "")
    assert list(tmp_path.iterdir()) == []
