"""Tighter speed weights over a push-off (ridempc.mpc.push_weights): the skateboard's
problems weigh the CoM's and the board's speeds by the pair's push tolerances until the
push-off entry ends, and no other problem changes."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc import LinearMpc
from ridempc.mpc.push_weights import pushing, with_push_weights


@pytest.fixture(scope="module")
def skate() -> LinearMpc:
    return LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)


def _problem(mpc: LinearMpc, t: float):
    x0 = mpc.reference.states_at(np.array([t]))[0]
    return mpc.problem(t, x0)


def test_a_push_off_weighs_the_speeds_by_the_pairs_tolerances(skate) -> None:
    names = list(skate.reference.state_names)
    tolerances = skate.pair.push_tolerances
    assert set(tolerances) == {"vx", "board_v"}
    assert skate.reference.target <= skate.pair.push_max_target
    end = float(skate.reference.times[-1])
    assert pushing(skate.reference, 1.0) and not pushing(skate.reference, end)
    assert not pushing(skate.reference, -1.0)  # held at its start, before the command
    inside = _problem(skate, 1.0)
    wanted = skate.state_weights.copy()
    for name, sigma in tolerances.items():
        wanted[names.index(name)] = 1.0 / sigma**2
    np.testing.assert_array_equal(inside.state_weights, wanted)
    np.testing.assert_array_equal(inside.terminal_weights, skate.terminal_factor * wanted)
    assert inside.state_weights[names.index("vx")] > skate.state_weights[names.index("vx")]
    after = _problem(skate, end + 0.5)  # riding on past the push-off: the usual weights
    np.testing.assert_array_equal(after.state_weights, skate.state_weights)


def test_push_offs_beyond_the_pairs_largest_target_keep_their_weights() -> None:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 1.0)
    assert mpc.reference.target > mpc.pair.push_max_target
    assert not pushing(mpc.reference, 1.0, mpc.pair.push_max_target)
    np.testing.assert_array_equal(_problem(mpc, 1.0).state_weights, mpc.state_weights)


def test_rides_without_a_push_keep_their_weights() -> None:
    mpc = LinearMpc.from_library("cassie", "hovershoes", "accelerate", 0.5)
    assert not mpc.pair.push_tolerances and not pushing(mpc.reference, 0.5)
    np.testing.assert_array_equal(_problem(mpc, 0.5).state_weights, mpc.state_weights)


def test_bad_tolerances_are_named(skate) -> None:
    problem = _problem(skate, 1.0)
    with pytest.raises(ValueError, match="'board_speed' names no state"):
        with_push_weights(problem, skate.reference, 1.0, {"board_speed": 0.05}, 10.0)
    with pytest.raises(ValueError, match="'vx' must be positive"):
        with_push_weights(problem, skate.reference, 1.0, {"vx": 0.0}, 10.0)
