"""Pushing the skateboard again while it rolls: the rolling-start schedule, state and
problem (``repush`` entries), and the rider choosing to push when the board has slowed."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.mpc.manoeuvre import REPUSH, REPUSH_BAND, Manoeuvre, ManoeuvreSelector
from ridempc.mpc.problem import MpcProblem
from ridempc.scenarios.scenario import Command
from ridempc.trajopt.pairs import EntrySpec, load_pair
from ridempc.trajopt.schedule import push_schedule
from ridempc.trajopt.skate_pair import REPUSH_GAIN, repush_entry, skate_models
from ridempc.trajopt.skate_problem import initial_skate_state
from ridempc.trajopt.skateboard import BOARD_STATE
from tests.helpers import reference_problem


def test_a_rolling_start_needs_the_strides_of_the_speed_it_gains() -> None:
    from_rest = push_schedule(0.7, 4, 2)
    rolling = push_schedule(0.7, 4, 2, start_speed=0.5)
    pushes = [p for p in rolling.phases if p.mode == "push"]
    assert len(pushes) == 2 < len([p for p in from_rest.phases if p.mode == "push"])
    assert rolling.phases[0].mode == rolling.phases[-1].mode == "four-leg"


def test_the_rolling_start_state_rides_with_the_board() -> None:
    robot, board = skate_models("cyberdog2", "skateboard")
    rest, places = initial_skate_state(robot, board)
    rolling, same_places = initial_skate_state(robot, board, 0.5)
    nr = 12 + robot.n_joints
    assert rolling[6] == 0.5 and rolling[nr + BOARD_STATE.index("board_v")] == 0.5
    changed = np.flatnonzero(rolling != rest)
    assert set(changed) == {6, nr + BOARD_STATE.index("board_v")}
    np.testing.assert_array_equal(places, same_places)


def test_a_repush_problem_starts_rolling_and_ends_at_its_target() -> None:
    """Built, not solved (IPOPT takes 40 s): node 0 fixed at the rolling start, the last
    node's speed at the target, the speed reference ramped from the one to the other."""
    PAIR = load_pair("cyberdog2", "skateboard")

    spec = repush_entry(0.7)
    assert spec.name == "repush-0.70" and spec.options["start_speed"] == pytest.approx(0.5)
    PAIR.check(spec)
    problem = PAIR.build(spec)
    assert problem.metadata["kind"] == REPUSH
    assert problem.metadata["options"]["start_speed"] == pytest.approx(0.5)
    names = list(problem.state_names)
    first = problem.lbw[: problem.nx] * problem.state_scale
    assert first[names.index("board_v")] == pytest.approx(0.5)
    assert first[names.index("vx")] == pytest.approx(0.5)
    with pytest.raises(ConfigError, match="start_speed"):
        PAIR.check(EntrySpec("repush", 0.7))  # a re-push from rest is an accelerate


def test_the_rider_pushes_again_once_the_board_has_slowed() -> None:
    selector = ManoeuvreSelector("cyberdog2", "skateboard")
    selector.targets = {**selector.targets, REPUSH: (0.5, 0.7, 1.0)}
    assert REPUSH_BAND == REPUSH_GAIN  # pushed when the board is at the entry's start
    coasting = Manoeuvre("accelerate", 0.7, 0.5)
    command = Command(velocity=0.7)
    assert selector.repush(command, coasting, 9.0, 0.49) is coasting  # a push-off coasts on
    selector.holds_speed = True  # the scenario holds its speed (push_off.hold)
    assert selector.repush(command, coasting, 9.0, 0.6) is coasting  # not slow enough yet
    pushed = selector.repush(command, coasting, 9.0, 0.49)
    assert (pushed.kind, pushed.target, pushed.start) == (REPUSH, 0.7, 9.0)
    assert selector.repush(Command(velocity=0.0), coasting, 9.0, 0.2) is coasting  # rest
    # a running re-push is kept while the command holds, and starts at its rolling start
    # (its speed phase matched instead, a rider a little faster joined it mid-push)
    assert selector.select(command, pushed, 9.5, 0.55) is pushed
    times = np.linspace(0.0, 2.0, 5)
    speeds = np.array([0.5, 0.45, 0.5, 0.6, 0.7])
    assert ManoeuvreSelector.phase_start(times, speeds, 0.52, 9.0, REPUSH) == 9.0


def _problem(x0: np.ndarray, window: np.ndarray, dt: float) -> MpcProblem:
    """An MPC problem around the state reference ``window`` (its dynamics unused)."""
    return reference_problem(x0, window, dt)


def test_a_switched_reference_is_blended_in_from_the_rider_before_the_first_push() -> None:
    """The offset between the rider and the re-push's first knot (the body 3 cm further
    forward on the deck) is laid over the reference at the switch and gone by the first
    push; the centre of mass's velocity row carries the blend's rate."""
    from ridempc.mpc.manoeuvre import StateLayout
    from ridempc.mpc.pairs import load_mpc_pair
    from ridempc.mpc.reference import select_reference
    from ridempc.mpc.switch_blend import SwitchBlend, first_push_time

    reference = select_reference("cyberdog2", "skateboard", "accelerate", 0.7)
    layout = StateLayout.from_pair(reference.state_names, load_mpc_pair("cyberdog2", "skateboard"))
    names = layout.names
    push = first_push_time(reference)
    assert 0.5 < push < reference.duration
    x0 = reference.states_at(np.array([0.0]))[0].copy()
    x0[names["com_x"]] += 0.05  # 3 cm ahead of the knot on a deck 2 cm further on
    x0[names["board_x"]] += 0.02
    x0[names["q_FL_knee"]] += 0.1
    n, dt = 40, 0.05
    window = reference.states_at(dt * np.arange(n + 1))
    problem = _problem(x0, window, dt)
    blend = SwitchBlend.at_switch(problem, reference, layout, 0.0)
    assert blend.offsets[names["com_x"]] == pytest.approx(0.03)
    assert blend.offsets[names["board_x"]] == 0.0
    assert blend.offsets[names["q_FL_knee"]] == pytest.approx(0.1)
    assert blend.duration == pytest.approx(push)
    blended = blend(problem, 0.0).state_reference
    shift = blended - window
    np.testing.assert_allclose(shift[0], blend.offsets, atol=1e-12)  # starts at the rider
    after = dt * np.arange(n + 1) >= push
    np.testing.assert_allclose(shift[after], 0.0, atol=1e-12)  # gone by the first push
    vx = shift[:, names["vx"]]
    assert np.all(vx <= 1e-12) and vx.min() < 0.0  # the body eased back as the offset fades
    assert not blend.done(0.0) and blend.done(push)


def test_the_committed_library_holds_the_repush_entries_its_pair_builds() -> None:
    """``ridempc library build`` makes the re-pushes whose rolling start is no slower than
    the least target, and the committed library holds them (the rider reads them)."""
    PAIR = load_pair("cyberdog2", "skateboard")

    names = [s.name for s in PAIR.entries(PAIR.default_targets)]
    assert [n for n in names if n.startswith(REPUSH)] == [
        "repush-0.50",
        "repush-0.70",
        "repush-1.00",
    ]
    assert ManoeuvreSelector("cyberdog2", "skateboard").targets[REPUSH] == (0.5, 0.7, 1.0)


def test_holding_the_speed_is_refused_where_the_library_cannot_push_again() -> None:
    """``push_off.hold`` needs ``repush`` entries: the skateboard's library has them, the
    hovershoes' has none (exit 2 from the CLI, naming the field)."""
    from ridempc.scenarios.hold import check_hold
    from ridempc.scenarios.scenario import Scenario

    held = Scenario.model_validate(
        {
            "name": "held",
            "duration": 5.0,
            "push_off": {"target": 0.7, "judged_at": 5.0, "hold": True},
        }
    )
    check_hold(held, "cyberdog2", "skateboard")
    check_hold(held, None, "skateboard")  # a dead weight holds nothing
    with pytest.raises(ConfigError, match=r"field 'push_off.hold' is true; allowed: .*repush"):
        check_hold(held, "cassie", "hovershoes")


def test_a_repush_after_its_first_push_gains_its_planned_speed_from_the_board() -> None:
    """The reference's forward speeds shifted by the board's deficit at node 0, the gain over
    the horizon kept, and the places moved by the same speed integrated."""
    from ridempc.mpc.manoeuvre import StateLayout
    from ridempc.mpc.pairs import load_mpc_pair
    from ridempc.mpc.push_gain import shifted_speeds
    from ridempc.mpc.reference import select_reference
    from ridempc.mpc.switch_blend import first_push_time

    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    layout = StateLayout.from_pair(reference.state_names, load_mpc_pair("cyberdog2", "skateboard"))
    names = layout.names
    n, dt = 30, 0.05
    window = reference.states_at(first_push_time(reference) + dt * np.arange(n + 1))
    window[:, names["board_yaw"]] += 0.3  # a board turned in the library frame
    problem = _problem(window[0].copy(), window, dt)
    slower = window[0, names["board_v"]] - 0.1
    shifted = shifted_speeds(problem, layout, slower).state_reference
    change = shifted - window
    assert shifted[0, names["board_v"]] == pytest.approx(slower)
    np.testing.assert_allclose(change[:, names["board_v"]], -0.1)  # the gain is kept
    heading = window[:, names["board_yaw"]]
    np.testing.assert_allclose(change[:, names["vx"]], -0.1 * np.cos(heading))
    np.testing.assert_allclose(change[:, names["vy"]], -0.1 * np.sin(heading))
    for axis, trig in (("x", np.cos), ("y", np.sin)):
        steps = np.diff(change[:, names[f"board_{axis}"]])
        np.testing.assert_allclose(steps, -0.1 * trig(heading[:-1]) * dt, atol=1e-12)
        np.testing.assert_allclose(
            change[:, names[f"com_{axis}"]], change[:, names[f"board_{axis}"]]
        )
    assert change[0, names["com_x"]] == 0.0 and not np.any(change[:, names["com_z"]])
