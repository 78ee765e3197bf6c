"""After a push-off the skateboard's reference settles the dog back over its four feet
(ridempc.mpc.settle): nothing changes before the end, and ``settle_time`` after it the
centre of mass stands where it started on the board, the feet where they ended, and the
forces share the weight as at the start."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.pairs import load_mpc_pair
from ridempc.mpc.settle import settle_over_feet
from ridempc.pair_description import load_pair_description
from ridempc.trajopt.rigid_body import feet_world
from ridempc.trajopt.skate_pair import skate_models

# [s] the skateboard pair's settle over its feet (its pair file's ``stages.settle``)
_settle = load_pair_description("cyberdog2", "skateboard").stages.settle
assert _settle is not None
SETTLE_TIME = _settle.duration


def _on_board(reference, states: np.ndarray) -> np.ndarray:
    """The centre of mass's place on the board, in the board's axes [m], per row."""
    i = reference.state_names.index
    yaw = states[:, i("board_yaw")]
    dx = states[:, i("com_x")] - states[:, i("board_x")]
    dy = states[:, i("com_y")] - states[:, i("board_y")]
    return np.stack([np.cos(yaw) * dx + np.sin(yaw) * dy, -np.sin(yaw) * dx + np.cos(yaw) * dy], 1)


@pytest.fixture(scope="module")
def settled():
    """The 1.0 m/s push-off's reference as the MPC rides it (settled), and held (not)."""
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 1.0)
    held = mpc.reference
    assert held.settle_states is not None and held.settle_time == SETTLE_TIME
    held = replace(held, settle_states=None, settle_inputs=None, settle_time=0.0)
    return mpc.reference, held


def test_nothing_changes_before_the_end(settled) -> None:
    reference, held = settled
    times = np.linspace(0.0, reference.times[-1], 37)
    assert np.array_equal(reference.states_at(times), held.states_at(times))
    window, plain = reference.sample(1.0, 12, 1 / 30), held.sample(1.0, 12, 1 / 30)
    assert np.array_equal(window.inputs, plain.inputs)


def test_the_centre_of_mass_goes_back_over_the_feet(settled) -> None:
    reference, held = settled
    robot, _ = skate_models("cyberdog2", "skateboard")
    end = reference.times[-1]
    times = np.array([end, end + 0.5 * SETTLE_TIME, end + SETTLE_TIME, end + 3.0])
    states, still = reference.states_at(times), held.states_at(times)
    start = _on_board(reference, reference.states[:1])[0]
    place = _on_board(reference, states)
    assert place[0, 0] - start[0] > 0.08  # the 1.0 m/s entry ends 8.7 cm ahead of the start
    assert np.allclose(place[2:], start, atol=1e-9)  # back where it started, and stays
    # halfway in time, halfway there (the smoothstep's middle)
    assert place[1] == pytest.approx(0.5 * (place[0] + place[2]), abs=1e-9)
    joints = [k for k, n in enumerate(reference.state_names) if n.startswith("q_")]
    for settled_row, held_row in zip(states[2:], still[2:], strict=True):
        # every foot where the held reference has it: the joints follow the trunk's move
        feet = feet_world(robot, settled_row[0:3], settled_row[3:6], settled_row[joints], np)
        kept = feet_world(robot, held_row[0:3], held_row[3:6], held_row[joints], np)
        assert np.allclose(feet, kept, atol=1e-6)
        assert np.allclose(settled_row[2:6], held_row[2:6])  # height and attitude kept


def test_the_forces_are_shared_as_at_the_start(settled) -> None:
    reference, _ = settled
    window = reference.sample(reference.times[-1] + SETTLE_TIME, 4, 1 / 30)
    first = reference.inputs[0]
    for rows in reference.force_index:
        # the push-off runs straight: its heading turns by well under a degree
        assert np.allclose(window.inputs[:, rows], first[rows], atol=0.05 * abs(first[rows[2]]))
    assert window.inputs[0, reference.force_index[:, 2]].sum() == pytest.approx(
        first[reference.force_index[:, 2]].sum(), rel=1e-3
    )


def test_a_reference_without_one_board_cannot_settle() -> None:
    shoes = LinearMpc.from_library("cassie", "hovershoes", "accelerate", 1.0).reference
    assert shoes.settle_states is None  # the Hovershoes do not settle
    robot, _ = skate_models("cyberdog2", "skateboard")
    with pytest.raises(ConfigError, match="settle"):
        settle_over_feet(shoes, robot, 1.0, load_mpc_pair("cassie", "hovershoes").board_states)


def test_a_settle_the_legs_cannot_reach_is_refused(settled) -> None:
    """A reference whose start stood a metre further back on the board: no joint angles
    keep the feet where they ended, and the error says so in one line."""
    reference, _ = settled
    robot, _ = skate_models("cyberdog2", "skateboard")
    states = reference.states.copy()
    states[0, reference.state_names.index("com_x")] -= 1.0
    far = replace(reference, states=states, settle_states=None, settle_inputs=None)
    with pytest.raises(ConfigError, match="no joint angles keep the feet in place") as info:
        settle_over_feet(far, robot, 1.0, load_mpc_pair("cyberdog2", "skateboard").board_states)
    assert "\n" not in str(info.value)
