"""The plan's first step read as whole-body targets (:mod:`ridempc.mpc.plan_targets`), against
the per-coordinate formulas it replaced: the hand-written Z-Y-X matrix and quaternion, each
contact's force turned one by one."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.plan import Plan
from ridempc.mpc.plan_targets import PlanReader
from ridempc.mpc.state_map import PlanarFrame
from ridempc.rotations import matrix_to_quaternion
from ridempc.trajopt.rotations import euler_zyx_matrix

NAMES = ("com_x", "com_y", "com_z", "base_roll", "base_pitch", "base_yaw")
NAMES += ("vx", "vy", "vz", "wx", "wy", "wz", "board_x")
INDEX = {name: i for i, name in enumerate(NAMES)}
FORCE_INDEX = np.array([[0, 1, 2], [3, 4, 5], [6, 7, 8]])
CONTACT_FOOT = (0, 0, 1)  # two contacts on the first foot, one on the second
DT = 1.0 / 30.0  # the MPC's step [s]


def _by_coordinate(plan: Plan, frame: PlanarFrame, share: float, feedforward: float) -> dict:
    """The rider's former per-coordinate targets."""
    n = INDEX
    x = plan.first_step_state(share)
    rotation = euler_zyx_matrix(x[n["base_roll"]], x[n["base_pitch"]], x[n["base_yaw"]] + frame.yaw)
    step = feedforward * (plan.states[1] - plan.states[0]) / DT
    forces = np.zeros((2, 3))
    site_forces = np.zeros((3, 3))
    for i, foot in enumerate(CONTACT_FOOT):
        f = frame.vector_to_world(plan.first_input[FORCE_INDEX[i]])
        site_forces[i] = f
        forces[foot] += f
    return {
        "position": frame.point_to_world(np.array([x[n["com_x"]], x[n["com_y"]], x[n["com_z"]]])),
        "velocity": frame.vector_to_world(np.array([x[n["vx"]], x[n["vy"]], x[n["vz"]]])),
        "rotation": rotation,
        "orientation": matrix_to_quaternion(rotation),
        "angular_velocity": rotation @ np.array([x[n["wx"]], x[n["wy"]], x[n["wz"]]]),
        "acceleration": frame.vector_to_world(step[[n["vx"], n["vy"], n["vz"]]]),
        "angular_acceleration": rotation @ step[[n["wx"], n["wy"], n["wz"]]],
        "forces": forces,
        "site_forces": site_forces,
    }


@pytest.mark.parametrize("feedforward", [0.0, 0.5])
def test_plan_targets_match_the_per_coordinate_formulas(feedforward: float) -> None:
    rng = np.random.default_rng(11)
    reader = PlanReader(INDEX, "base_", FORCE_INDEX, CONTACT_FOOT, 2, feedforward, DT)
    for _ in range(200):
        states = rng.normal(size=(3, len(NAMES)))
        states[:, 3:6] = rng.uniform(-np.pi, np.pi, size=(3, 3))
        inputs = 50.0 * rng.normal(size=(2, 9))
        plan = Plan(states, inputs, inputs[0], "solved", 0.0, False)
        frame = PlanarFrame(float(rng.uniform(-np.pi, np.pi)), tuple(rng.normal(size=2)))
        share = float(rng.uniform(-0.2, 1.2))
        got = reader(plan, frame, share)._asdict()
        want = _by_coordinate(plan, frame, share, feedforward)
        if not feedforward:
            want["acceleration"] = want["angular_acceleration"] = np.zeros(3)
        for key, value in want.items():
            np.testing.assert_allclose(got[key], value, rtol=0, atol=1e-12, err_msg=key)


@pytest.mark.parametrize("feedforward", [0.0, 0.5])
def test_a_plan_read_again_gives_what_a_fresh_reader_gives(feedforward: float) -> None:
    """The targets kept per plan and frame: the same plan read at other shares, then a new
    plan and a new frame, each equal to the bit to a reader that never read before."""
    rng = np.random.default_rng(12)
    reader = PlanReader(INDEX, "base_", FORCE_INDEX, CONTACT_FOOT, 2, feedforward, DT)
    plans = [
        Plan(rng.normal(size=(3, len(NAMES))), inputs, inputs[0], "solved", 0.0, False)
        for inputs in (50.0 * rng.normal(size=(2, 9)) for _ in range(2))
    ]
    frames = [PlanarFrame(float(rng.uniform(-np.pi, np.pi)), (0.1, -0.2)) for _ in range(2)]
    for plan, frame in ((plans[0], frames[0]), (plans[0], frames[1]), (plans[1], frames[1])):
        for share in (0.0, 0.4, 1.0):
            got = reader(plan, frame, share)._asdict()
            fresh = PlanReader(INDEX, "base_", FORCE_INDEX, CONTACT_FOOT, 2, feedforward, DT)
            for key, value in fresh(plan, frame, share)._asdict().items():
                assert np.array_equal(got[key], value), key
    assert not reader(plans[1], frames[1], 0.5).forces.flags.writeable
