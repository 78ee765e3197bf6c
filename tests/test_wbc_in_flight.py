"""The torques in flight through the motors' delay and the least site forces they ask for."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from ridempc.robots import load_robot
from ridempc.wbc.in_flight import TorquesInFlight
from ridempc.wbc.model import WholeBodyModel

DT = 0.002  # the WBC's tick [s]


@pytest.fixture(scope="module")
def cassie() -> tuple[WholeBodyModel, TorquesInFlight]:
    robot = load_robot("cassie")
    model = WholeBodyModel(robot)
    return model, TorquesInFlight(model, robot, DT)


def _motor(name: str) -> int:
    return [m.name for m in load_robot("cassie").motors].index(name)


def test_each_line_foot_is_turned_by_its_toe_across_its_sites(
    cassie: tuple[WholeBodyModel, TorquesInFlight],
) -> None:
    model, in_flight = cassie
    assert in_flight.window == 3  # 3 ms over 2 ms ticks, rounded up, and the arriving one
    for site, frame in enumerate(model.site_frames):
        side = model.model.frames[frame].name.split("_")[0]
        assert in_flight.site_motor[site] == _motor(f"{side}_toe")
    first, second = model.site_frames[:2]
    data = model.model.createData()
    pin.framesForwardKinematics(model.model, data, pin.neutral(model.model))
    lever = np.linalg.norm(data.oMf[first].translation - data.oMf[second].translation)
    assert in_flight.site_lever[:2] == pytest.approx([lever, lever])
    assert lever == pytest.approx(0.16, abs=0.01)


@pytest.mark.parametrize("swing", [0.5, 4.0, 40.0])
def test_a_toe_torque_swing_holds_both_sites_of_its_foot(swing: float) -> None:
    robot = load_robot("cassie")
    model = WholeBodyModel(robot)
    in_flight = TorquesInFlight(model, robot, DT)
    feet = np.array([160.0, 160.0])
    assert in_flight.least_forces(0.0, feet) is None  # nothing recorded yet
    torque = np.zeros(len(robot.motors))
    in_flight.record(0.0, torque)
    torque[_motor("left_toe")] = swing
    in_flight.record(DT, torque)
    assert in_flight.least_forces(DT, feet) is None  # a QP solved again at the same time
    least = in_flight.least_forces(2 * DT, feet)
    assert least is not None
    left = in_flight.site_foot == model.foot_names.index("left_foot")
    expected = min(swing / in_flight.site_lever[left][0], 0.5 * feet[0])
    assert least[left] == pytest.approx(expected)
    assert np.all(least[~left] == 0.0)
    assert in_flight.least_forces(6 * DT, feet) is None  # after a gap: those have arrived


def test_without_a_delay_nothing_is_in_flight() -> None:
    robot = load_robot("cyberdog2")
    model = WholeBodyModel(robot)
    in_flight = TorquesInFlight(model, robot, DT)
    assert in_flight.window == 0
    for tick in range(4):
        in_flight.record(tick * DT, np.arange(len(robot.motors), dtype=float) * tick)
    assert in_flight.least_forces(4 * DT, np.full(len(model.foot_names), 30.0)) is None


@pytest.mark.parametrize("shape", ["box", "diamond"])
def test_the_pyramid_raises_an_active_sites_least_normal_force(shape: str) -> None:
    from dataclasses import replace

    from ridempc.wbc.constraints import FrictionPyramidConstraint
    from ridempc.wbc.contacts import ContactSet
    from ridempc.wbc.layout import DecisionLayout

    layout = DecisionLayout(nv=6, n_sites=3, n_motors=0)
    constraint = FrictionPyramidConstraint(layout, 0.6, 0.0, 100.0, shape)
    contacts = ContactSet.on_ground(np.array([True, True, False]))
    plain = constraint.compute_qp_constraint(None, None, contacts)
    least = np.array([12.0, 0.0, 30.0])
    held = constraint.compute_qp_constraint(None, None, replace(contacts, least_force=least))
    normal = 5 * np.arange(3) + 4
    assert held.lower[normal[0]] == 12.0  # active and bounded
    assert held.lower[normal[1]] == plain.lower[normal[1]]  # active, no bound
    assert held.lower[normal[2]] == plain.lower[normal[2]] == 0.0  # in the air: still none
    others = np.setdiff1d(np.arange(15), normal[:1])
    np.testing.assert_array_equal(held.lower[others], plain.lower[others])
    np.testing.assert_array_equal(held.upper, plain.upper)
