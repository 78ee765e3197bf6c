"""The quadruped-skateboard NLP: refused targets, structure, bounds (built, not solved)."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.pair_description import load_pair_description
from ridempc.trajopt.pairs import EntrySpec, load_pair
from ridempc.trajopt.schedule import Contact
from ridempc.trajopt.skate_pair import skate_models, skate_options
from ridempc.trajopt.skate_problem import initial_skate_state, skate_schedule


@pytest.mark.parametrize("target", [20.0, 0.0, -0.5])
def test_unreachable_targets_are_refused_up_front(target: float) -> None:
    pair = load_pair("cyberdog2", "skateboard")
    with pytest.raises(ConfigError, match="unreachable"):
        pair.check(EntrySpec("accelerate", target))


def test_unknown_pair_and_option_are_refused() -> None:
    with pytest.raises(UnknownNameError, match="cyberdog2-skateboard"):
        load_pair("cassie", "skateboard")
    with pytest.raises(ConfigError, match="unknown skateboard option 'dtt'"):
        skate_options({"dtt": 0.1})


def test_initial_state_stands_on_the_deck() -> None:
    robot, board = skate_models("cyberdog2", "skateboard")
    state, on_deck = initial_skate_state(robot, board)
    assert np.allclose(on_deck[:, 2], robot.foot_radius, atol=5e-3)  # feet on the deck top
    assert np.all(np.abs(on_deck[:, 1]) < board.half_width)  # and inside its width
    assert np.all(np.abs(on_deck[:, 0]) < board.half_length)
    assert np.allclose(state[3:12], 0.0)


def test_problem_structure_and_bounds() -> None:
    pair = load_pair("cyberdog2", "skateboard")
    problem = pair.build(EntrySpec("accelerate", 0.3))
    robot, board = skate_models("cyberdog2", "skateboard")
    n, nx, nu = problem.n_intervals, problem.nx, problem.nu
    assert (nx, nu) == (30, 24)
    assert problem.variables.shape[0] == n * (2 * nx + nu) + nx
    assert problem.constraints.shape[0] == len(problem.lbg) == len(problem.ubg)
    assert problem.times[-1] == pytest.approx(0.3 + 1.2 + 0.6 + 0.3)
    # Node 0 is the keyframe at rest, fixed by its bounds.
    x0, _ = initial_skate_state(robot, board)
    assert np.allclose(problem.lbw[:nx], x0) and np.allclose(problem.ubw[:nx], x0)
    # The pushing foot carries no force while it swings; joint speeds within 31 rad/s.
    defaults = load_pair_description("cyberdog2", "skateboard").trajopt.problem_options()
    masks = skate_schedule(robot, 0.3, skate_options({}, defaults)).contact_masks()
    stride = 2 * nx + nu
    upper = problem.ubw[: n * stride].reshape(n, stride)[:, nx : nx + nu] * problem.input_scale
    pusher = robot.feet.index("RL_contact")
    swinging = masks[Contact.SWING][:, pusher] == 1
    assert swinging.any()
    assert np.all(upper[swinging, 3 * pusher : 3 * pusher + 3] == 0.0)
    assert np.all(upper[~swinging, 3 * pusher + 2] > 0.0)
    assert np.allclose(upper[:, 12:], 31.0)
    # Board roll within its bottom-out angle at every node after the first.
    roll = problem.state_names.index("board_roll")
    lower_states = problem.lbw[: n * stride].reshape(n, stride)[1:, roll]
    assert np.allclose(lower_states, -board.roll_limit)
