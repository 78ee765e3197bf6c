"""Mirror images of a symmetric robot's trajectories (y -> -y, left and right feet exchanged),
and the re-push's side chosen by the commanded turn."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.mpc.mirrored import mirrored
from ridempc.mpc.pairs import load_mpc_pair
from ridempc.mpc.push_side import TURN_BAND, PushSide, pusher_side
from ridempc.mpc.reference import select_reference
from ridempc.trajopt.mirror import Mirror, robot_symmetry
from ridempc.trajopt.schedule import Contact
from ridempc.trajopt.skate_pair import skate_models

ROBOTS = ("cyberdog2", "go1")


@pytest.mark.parametrize("name", ROBOTS)
def test_the_feet_and_joints_pair_by_the_kinematics(name: str) -> None:
    robot, _ = skate_models(name, "skateboard")
    symmetry = robot_symmetry(robot)
    feet = robot.feet
    for i, j in enumerate(symmetry.foot_mirror):
        assert symmetry.foot_mirror[j] == i and symmetry.side[i] == -symmetry.side[j]
        assert feet[i][0] == feet[j][0] and feet[i][1] != feet[j][1]  # FL <-> FR, RL <-> RR
    for k, joint in enumerate(robot.joints):
        other = robot.joints[symmetry.joint_mirror[k]]
        assert joint.split("_")[1] == other.split("_")[1]  # abad <-> abad, knee <-> knee
        assert symmetry.joint_sign[k] == (-1.0 if joint.endswith("abad") else 1.0)


def test_a_robot_that_is_not_symmetric_is_refused() -> None:
    robot, _ = skate_models("cyberdog2", "skateboard")
    bent = robot.q_reference.copy()
    bent[0] += 0.3  # one ab/adduction only
    with pytest.raises(ConfigError, match="not left-right symmetric"):
        robot_symmetry(dataclasses.replace(robot, q_reference=bent))


def _exact_symmetric_pair() -> tuple[Mirror, object, object]:
    """The CyberDog2 made exactly symmetric (its CoM 0.12 mm off its plane and its inertia's
    xy product of 2e-4 kg m^2 removed), its re-push entry and its dynamics."""
    pair = load_mpc_pair("cyberdog2", "skateboard")
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    robot, board = skate_models("cyberdog2", "skateboard")
    inertia = robot.inertia.copy()
    inertia[0, 1] = inertia[1, 0] = inertia[1, 2] = inertia[2, 1] = 0.0
    com = robot.com_in_trunk * np.array([1.0, 0.0, 1.0])
    robot = dataclasses.replace(robot, inertia=inertia, com_in_trunk=com)
    from ridempc.trajopt.skate_problem import skate_rates

    mirror = Mirror.of(
        robot_symmetry(robot), reference.state_names, reference.input_names, pair.board_states
    )
    return mirror, reference, skate_rates(robot, board)


def test_a_mirrored_trajectory_obeys_the_same_dynamics() -> None:
    """f(M x, M u, M p) = M f(x, u, p) at every node of a re-push, with the feet swapped,
    the push made by the other rear foot."""
    mirror, reference, rates = _exact_symmetric_pair()
    for k in range(0, len(reference.inputs), 4):
        x, u, p = reference.states[k], reference.inputs[k], reference.parameters[k]
        straight = mirror.rates(np.asarray(rates(x, u, p)).ravel())
        reflected = np.asarray(
            rates(mirror.states(x), mirror.inputs(u), mirror.per_contact(p))
        ).ravel()
        np.testing.assert_allclose(reflected, straight, atol=1e-9)


def test_mirroring_twice_gives_the_trajectory_back() -> None:
    pair = load_mpc_pair("cyberdog2", "skateboard")
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    mirror = Mirror.of(
        pair.symmetry, reference.state_names, reference.input_names, pair.board_states
    )
    once = mirrored(reference, mirror)
    twice = mirrored(once, mirror)
    np.testing.assert_allclose(twice.states, reference.states, atol=1e-12)
    np.testing.assert_allclose(twice.inputs, reference.inputs, atol=1e-12)
    assert twice.schedule == reference.schedule
    assert once.metadata["options"]["pusher"] == "RR_contact"
    names = list(reference.state_names)
    assert once.states[:, names.index("board_roll")] == pytest.approx(
        -reference.states[:, names.index("board_roll")]
    )
    assert pusher_side(reference, pair.symmetry) == 1.0  # the rear left foot
    assert pusher_side(once, pair.symmetry) == -1.0


def test_a_repush_pushes_from_the_side_away_from_the_turn() -> None:
    """A push turns the board away from its foot's side: a left turn (positive yaw rate) is
    pushed by the right foot; straight, the sides alternate."""
    pair = load_mpc_pair("cyberdog2", "skateboard")
    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    side = PushSide(pair.symmetry)

    def pusher(yaw_rate: float) -> float | None:
        chosen = side.reference(reference, yaw_rate, pair.board_states)
        return pusher_side(chosen, pair.symmetry)

    assert pusher(0.0) == 1.0  # the library's own, first
    assert pusher(0.0) == -1.0 and pusher(0.5 * TURN_BAND) == 1.0  # alternating
    assert pusher(0.2) == -1.0 and pusher(0.2) == -1.0  # left turn: right foot
    assert pusher(-0.2) == 1.0
    ground = [step.index(Contact.GROUND) for step in reference.schedule if Contact.GROUND in step]
    assert {reference.contact_names[i] for i in ground} == {"RL_contact"}
