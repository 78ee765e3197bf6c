"""The backup's reach after a falling platform, told by the rider's drop watch."""

from __future__ import annotations

import pytest

from ridempc.baselines.cassie_hovershoes import CassieHovershoes
from ridempc.controllers import make_controller
from ridempc.mpc.backup_reach import lend_drop_watch
from ridempc.mpc.drop import DropDetector
from ridempc.mpc.stages.triggers import DropWatch
from ridempc.robots import load_robot
from ridempc.scenarios.scenario import Command
from tests.test_hovershoe_flight import _packet

DT = 0.002  # [s] the control tick
LOADED, RELAXED = -0.04, 0.0  # [rad] shin springs standing, and with the foot unloaded


def _lengths(controller: CassieHovershoes, robot, shins: list[float]) -> list[float]:
    """The left leg's length target [m] after each tick of ``shins``, from a loaded start."""
    controller.update(_packet(robot, 0.0, shin=LOADED), Command())
    out = []
    for k, shin in enumerate(shins):
        controller.update(_packet(robot, (k + 1) * DT, shin=shin), Command())
        out.append(controller.diagnostics()["left_leg_length_target"])
    return out


def _pd(robot) -> CassieHovershoes:
    controller = make_controller("pd", robot, "hovershoes")
    assert isinstance(controller, CassieHovershoes)
    return controller


def test_a_foot_unloaded_by_a_push_keeps_its_leg_length() -> None:
    """Lent a witness that tells no drop, a foot unloaded well past the reach's delay (the
    rider tipped onto the other shoe) leaves its leg at its length; riding alone the PD
    reaches down."""
    robot = load_robot("cassie")
    shins = [LOADED] * 2 + [RELAXED] * 40  # 80 ms unloaded, four times the reach's delay
    alone = _lengths(_pd(robot), robot, shins)
    backup = _pd(robot)
    backup.shoes_falling = lambda: False
    lent = _lengths(backup, robot, shins)
    assert alone[-1] - alone[1] > 0.03  # the paper's PD reaches after the shoe
    assert lent[-1] == pytest.approx(lent[1], abs=1e-6)


def test_a_drop_told_once_lets_the_leg_reach_as_alone() -> None:
    """A witness that tells a drop as the foot unloads and then no more (its detector's
    reading flickers through the fall): the leg reaches as the PD's own, until loaded."""
    robot = load_robot("cassie")
    shins = [LOADED] * 2 + [RELAXED] * 40 + [LOADED] * 10
    alone = _lengths(_pd(robot), robot, shins)
    backup = _pd(robot)
    told = iter([True])
    backup.shoes_falling = lambda: next(told, False)
    assert _lengths(backup, robot, shins) == pytest.approx(alone, abs=1e-9)


def test_the_drop_watch_is_lent_only_to_a_law_with_a_flight_phase() -> None:
    robot = load_robot("cassie")
    watch = DropWatch(DropDetector())
    backup = _pd(robot)
    assert lend_drop_watch(backup, watch)
    assert backup.shoes_falling is not None and not backup.shoes_falling()
    watch.dropping = True
    assert backup.shoes_falling()
    assert not lend_drop_watch(_pd(robot), None)  # a pair without the drop stage
    segway = make_controller("pd", robot, "segway")
    assert not lend_drop_watch(segway, watch)  # a law without a flight phase
    assert getattr(segway, "shoes_falling", None) is None
