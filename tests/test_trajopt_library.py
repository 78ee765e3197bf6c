"""The committed motion libraries: every entry solved, its dynamics residual and drift small,
and the smallest quadruped entry rebuilt from scratch to the committed trajectory."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.library.store import library_folder, load_library
from ridempc.paths import motion_library_dir
from ridempc.trajopt.pairs import EntrySpec, load_pair, pair_names
from ridempc.trajopt.problem import collocation_defect, solve_trajectory
from ridempc.trajopt.ride_pair import ride_models
from ridempc.trajopt.ride_problem import ride_layout

# Largest collocation defect (state units) a committed entry may have: IPOPT's constraint
# tolerance is 1e-8 on the scaled problem.
RESIDUAL_TOLERANCE = 1e-6
# Largest one-interval gap to an RK45 re-simulation (state units), and the board-only rollout's.
DRIFT_TOLERANCE = 5e-3
# Rebuilt vs committed: states [SI] and inputs relative to their largest magnitude.
REBUILD_STATE_TOLERANCE = 1e-4
REBUILD_INPUT_TOLERANCE = 1e-3
# Largest excursion of a Cassie entry's centre of mass from its riding height [m].
HEIGHT_TOLERANCE = 0.03

PAIRS = [name for name in pair_names() if (motion_library_dir() / name / "manifest.json").exists()]


def _split(name: str) -> tuple[str, str]:
    robot, board = name.split("-", 1)
    return robot, board


def test_the_default_quadruped_library_is_committed() -> None:
    assert "cyberdog2-skateboard" in PAIRS
    manifest, _ = load_library(library_folder("cyberdog2", "skateboard"))
    targets = {e.target for e in manifest.entries if e.kind == "accelerate"}
    assert {0.3, 0.5, 0.7, 1.0} <= targets


@pytest.mark.parametrize("pair_name", PAIRS)
def test_committed_entries_residual_and_drift(pair_name: str) -> None:
    pair = load_pair(*_split(pair_name))
    manifest, entries = load_library(library_folder(pair.robot, pair.board))
    assert entries
    for entry in entries:
        record = entry.record
        assert record.status == "Solve_Succeeded"
        defect = collocation_defect(pair.rates(record.metadata), record.dt)
        raw = defect.map(record.n_intervals)(
            entry.states[:-1].T,
            entry.midpoints.T,
            entry.states[1:].T,
            entry.inputs.T,
            entry.parameters.T,
        )
        residual = float(np.max(np.abs(np.asarray(raw))))
        assert residual < RESIDUAL_TOLERANCE, f"{record.name}: residual {residual:.2e}"
        assert residual == pytest.approx(record.max_violation, rel=1e-3, abs=1e-12)
        assert record.drift.local < DRIFT_TOLERANCE, record.name
        assert record.drift.board < DRIFT_TOLERANCE, record.name


def test_rebuilding_the_smallest_entry_reproduces_it() -> None:
    """The quadruped's smallest entry (48 intervals, about 10 s), from a cold start (the
    build's lowest target of a kind is never warm-started) with the stored options."""
    pair = load_pair("cyberdog2", "skateboard")
    _, entries = load_library(library_folder(pair.robot, pair.board))
    smallest = min(entries, key=lambda e: (e.record.n_intervals, e.record.target))
    record = smallest.record
    assert record.warm_start is None
    spec = EntrySpec(record.kind, record.target, dict(record.metadata.get("entry_options", {})))
    problem = pair.build(spec)
    guess = pair.guess(problem, None)
    solution = solve_trajectory(problem, guess.states, guess.inputs, guess.midpoints)
    assert solution.status == "Solve_Succeeded"
    assert np.allclose(solution.states, smallest.states, atol=REBUILD_STATE_TOLERANCE, rtol=0)
    scale = np.max(np.abs(smallest.inputs), axis=0) + 1e-9
    assert np.max(np.abs(solution.inputs - smallest.inputs) / scale) < REBUILD_INPUT_TOLERANCE


@pytest.mark.parametrize("pair_name", [name for name in PAIRS if name.startswith("cassie-")])
def test_the_rider_keeps_its_riding_height(pair_name: str) -> None:
    """Every Cassie entry keeps the centre of mass within ``HEIGHT_TOLERANCE`` of the riding
    keyframe's height: a crouch the task does not ask for puts the shins on the Segway's
    knee pad, which then steers (the 3 and 4 m/s entries once sank 0.13 m)."""
    robot, board = _split(pair_name)
    rider, wheeled = ride_models(robot, board)
    height = ride_layout(rider, wheeled)["com_height"]
    _, entries = load_library(library_folder(robot, board))
    for entry in entries:
        sag = float(np.max(np.abs(entry.state("com_z") - height)))
        assert sag < HEIGHT_TOLERANCE, f"{entry.record.name}: {sag:.3f} m off {height:.3f} m"
