"""The committed motion libraries: every entry solved, its dynamics residual and drift small,
and the smallest quadruped entry rebuilt from scratch to the committed trajectory."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import casadi as ca
import numpy as np
import pytest

from ridempc.library.store import library_folder, load_library
from ridempc.pair_description import load_pair_description
from ridempc.paths import motion_library_dir
from ridempc.trajopt.pairs import EntrySpec, load_pair, pair_names
from ridempc.trajopt.problem import collocation_defect, solve_trajectory
from ridempc.trajopt.ride_pair import ride_models
from ridempc.trajopt.ride_problem import ride_layout
from ridempc.trajopt.rigid_body import GRAVITY, feet_world
from ridempc.trajopt.rotations import euler_zyx_matrix
from ridempc.trajopt.schedule import Contact
from ridempc.trajopt.skate_pair import skate_models, skate_options
from ridempc.trajopt.skate_problem import inward_distances, skate_schedule, triangle_turn

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
# The quadrupeds' libraries (a ``skate`` problem), each checked by the skateboard tests below.
SKATE_PAIRS = [
    name for name in PAIRS if load_pair_description(*name.split("-", 1)).trajopt.problem == "skate"
]


def _split(name: str) -> tuple[str, str]:
    robot, board = name.split("-", 1)
    return robot, board


@pytest.mark.parametrize(
    "pair_name",
    [n for n in pair_names() if load_pair_description(*_split(n)).trajopt.problem == "skate"],
)
def test_each_quadruped_library_is_committed(pair_name: str) -> None:
    """Every quadruped's pair file has its library, with its pair file's push-off targets."""
    assert pair_name in SKATE_PAIRS
    manifest, _ = load_library(library_folder(*_split(pair_name)))
    targets = {e.target for e in manifest.entries if e.kind == "accelerate"}
    assert set(load_pair_description(*_split(pair_name)).trajopt.default_targets) <= targets
    assert {0.3, 0.5, 0.7, 1.0} <= targets  # the skateboard's push-off-<v> scenarios


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


def _skate_entries(pair_name: str) -> Iterator[tuple[Any, Any, dict[Contact, np.ndarray]]]:
    """Each committed entry of a skateboard pair with its stored options and its schedule's
    masks."""
    robot, _ = skate_models(*_split(pair_name))
    _, entries = load_library(library_folder(*_split(pair_name)))
    for entry in entries:
        options = skate_options(entry.record.metadata["options"])
        yield entry, options, skate_schedule(robot, entry.record.target, options).contact_masks()


@pytest.mark.parametrize("pair_name", SKATE_PAIRS)
def test_the_dog_keeps_its_centre_of_mass_inside_the_feet_on_the_deck(pair_name: str) -> None:
    """While a foot swings (lift-off and touchdown nodes included) every skateboard entry
    keeps the centre of mass at least its ``support_margin`` inside the triangle of the three
    feet on the deck, measured here from the stored states with NumPy (the NLP imposes it in
    CasADi). Before the margin the entries left it on the triangle's diagonal when the
    pushing foot landed, and riders whose trunk tipped a little early fell."""
    robot, _ = skate_models(*_split(pair_name))
    nr = 12 + robot.n_joints
    for entry, options, masks in _skate_entries(pair_name):
        assert options.support_margin >= 0.01, entry.record.name
        swinging = masks[Contact.SWING].any(axis=1)
        checked = 0
        for k, x in enumerate(entry.states):
            around = [j for j in (k - 1, k) if 0 <= j < len(swinging) and swinging[j]]
            if not around:
                continue
            support = np.flatnonzero(masks[Contact.BOARD][around[-1]])
            assert len(support) == 3
            feet = feet_world(robot, x[0:3], x[3:6], x[12:nr], np)
            corners = [feet[i][0:2] for i in support]
            turn = triangle_turn(np.array(corners))
            margin = float(np.min(np.asarray(inward_distances(x[0:2], corners, turn))))
            assert margin >= options.support_margin - 1e-6, (
                f"{entry.record.name} at {entry.times[k]:.2f} s: {100 * margin:.2f} cm inside"
            )
            checked += 1
        assert checked > 0, entry.record.name


@pytest.mark.parametrize("pair_name", SKATE_PAIRS)
def test_the_pushing_foot_lands_nearly_still(pair_name: str) -> None:
    """In the grid step before it lands on the ground the pushing foot of every skateboard
    entry covers at most ``touchdown_step`` along each horizontal axis (without it, the
    1.0 m/s entry's foot reached the ground at the trunk's 1.1 m/s)."""
    robot, _ = skate_models(*_split(pair_name))
    nr = 12 + robot.n_joints
    for entry, options, masks in _skate_entries(pair_name):
        pusher = robot.feet.index(options.pusher)
        ground = masks[Contact.GROUND][:, pusher] > 0
        landings = [k for k in range(1, len(ground)) if ground[k] and not ground[k - 1]]
        assert landings, entry.record.name
        for k in landings:
            before, landed = (
                feet_world(robot, x[0:3], x[3:6], x[12:nr], np)[pusher]
                for x in entry.states[k - 1 : k + 1]
            )
            step = float(np.max(np.abs(landed[0:2] - before[0:2])))
            assert step <= options.touchdown_step + 1e-6, (
                f"{entry.record.name} at {entry.times[k]:.2f} s: {100 * step:.2f} cm"
            )


@pytest.mark.parametrize("pair_name", SKATE_PAIRS)
def test_the_pushing_foot_lifts_unloaded(pair_name: str) -> None:
    """In the grid step before it lifts off the ground the pushing foot of every skateboard
    entry carries at most ``liftoff_force`` weights per foot (without it, the 1.0 m/s entry's
    last push ended at 51 N, and push-off-1.0 seed 18 fell after it)."""
    robot, _ = skate_models(*_split(pair_name))
    weight_per_foot = robot.mass * GRAVITY / robot.n_feet
    for entry, options, masks in _skate_entries(pair_name):
        pusher = robot.feet.index(options.pusher)
        ground = masks[Contact.GROUND][:, pusher] > 0
        lifts = [k for k in range(len(ground) - 1) if ground[k] and not ground[k + 1]]
        assert lifts, entry.record.name
        normal = entry.input_names.index(f"f_{options.pusher}_z")
        for k in lifts:
            force = float(entry.inputs[k, normal])
            assert force <= options.liftoff_force * weight_per_foot + 1e-6, (
                f"{entry.record.name} at {entry.times[k]:.2f} s: {force:.1f} N"
            )


@pytest.mark.parametrize("pair_name", SKATE_PAIRS)
def test_the_stance_legs_stay_under_the_motor_curves(pair_name: str) -> None:
    """Every skateboard entry's stance-leg statics torques stay within ``torque_fraction`` of
    the motors' torque-speed curves at the entry's planned joint rates (the NLP's rows,
    measured here with NumPy): the curves hold for the committed entries."""
    robot, _ = skate_models(*_split(pair_name))
    nf, nr = robot.n_feet, 12 + robot.n_joints
    q = ca.SX.sym("q", robot.n_joints)
    jacobians = ca.Function("jacobians", [q], [robot.foot_jacobian(q, i) for i in range(nf)])
    for entry, options, _ in _skate_entries(pair_name):
        for k, u in enumerate(entry.inputs):
            x = entry.states[k]
            rotation = euler_zyx_matrix(x[3], x[4], x[5], np)
            jac = jacobians(x[12:nr])
            limit = options.torque_fraction * robot.curve.limit(u[3 * nf :])
            for i in range(nf):
                leg = list(robot.legs[i])
                torque = np.asarray(jac[i])[:, leg].T @ (rotation.T @ u[3 * i : 3 * i + 3])
                assert np.all(np.abs(torque) <= limit[leg] + 1e-6), (
                    f"{entry.record.name} at {entry.times[k]:.2f} s, foot {robot.feet[i]}"
                )
