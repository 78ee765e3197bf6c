"""The rider's stages alone (ridempc.mpc.stages), without a ride: the handover triggers'
order, the feet's support, the deck's axes and sides, the command source's horizon and the
re-push blend's life."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.controllers.base import Controller
from ridempc.mpc.controller import MpcSettings
from ridempc.mpc.divergence import DivergentDeviation
from ridempc.mpc.drop import DropDetector
from ridempc.mpc.handover import HANDOVER_DEVIATION
from ridempc.mpc.plan import Plan
from ridempc.mpc.stages.build import BuildInputs
from ridempc.mpc.stages.commands import CommandHorizon
from ridempc.mpc.stages.deck_roll import side_feet, to_deck
from ridempc.mpc.stages.manoeuvre_shapers import RepushBlend
from ridempc.mpc.stages.support import foot_support
from ridempc.mpc.stages.triggers import (
    DropWatch,
    HandoverCheck,
    diverging,
    handover_triggers,
    plan_failed,
)
from ridempc.mpc.stages.turn import TurnSoFar
from ridempc.scenarios.scenario import Command
from ridempc.trajopt.schedule import Contact


def _plan(fallback: bool = False) -> Plan:
    zeros = np.zeros((2, 1))
    return Plan(zeros, zeros[:1], np.zeros(1), "failed" if fallback else "solved", 0.0, fallback)


def _check(**changes: Any) -> HandoverCheck:
    calm = HandoverCheck(_plan(), 0.0, 0.0, False, True, DivergentDeviation())
    return calm._replace(**changes)


class _Pushed:
    """A push watch that always reads a push."""

    def __call__(self, check: HandoverCheck) -> str | None:
        return "a push"


def _reason(
    check: HandoverCheck, dropping: bool = False, pushed: bool = False, alone: bool = False
) -> str | None:
    drop = DropWatch(DropDetector())
    drop.dropping = dropping
    push = cast(Any, _Pushed()) if pushed else None
    for trigger in handover_triggers(drop, push, failures_only=alone):
        reason = trigger(check)
        if reason is not None:
            return reason
    return None


def test_the_triggers_give_the_first_reason_in_their_order() -> None:
    assert _reason(_check()) is None
    assert "MPC plan failed" in str(_reason(_check(plan=_plan(True)), dropping=True))
    assert "a drop" in str(_reason(_check(slack=0.1), dropping=True))
    assert "slack 0.1" in str(_reason(_check(slack=0.1), pushed=True))
    far = 2.0 * HANDOVER_DEVIATION
    assert _reason(_check(deviation=far), pushed=True) == "a push"
    assert "from the reference" in str(_reason(_check(deviation=far)))
    assert _reason(_check(deviation=far, stroke=True)) is None  # a re-push's stroke rides out


def test_a_pairs_deviation_bound_hands_over_within_it() -> None:
    near = 0.9 * HANDOVER_DEVIATION
    assert _reason(_check(deviation=near)) is None
    narrow = handover_triggers(None, None, deviation_bound=0.5 * HANDOVER_DEVIATION)
    reasons = [trigger(_check(deviation=near)) for trigger in narrow]
    assert any("from the reference" in str(reason) for reason in reasons)


def test_the_mpc_alone_hands_over_only_its_own_failures() -> None:
    far = 2.0 * HANDOVER_DEVIATION
    assert _reason(_check(deviation=far), pushed=True, alone=True) is None
    assert "MPC plan failed" in str(_reason(_check(plan=_plan(True)), alone=True))
    assert "a drop" in str(_reason(_check(), dropping=True, alone=True))
    assert "slack 0.1" in str(_reason(_check(slack=0.1), alone=True))


def test_a_divergence_hands_over_only_while_on_probation() -> None:
    heading = DivergentDeviation()
    heading.value, heading.rate = 2.0 * HANDOVER_DEVIATION, 5.0
    assert _reason(_check(divergence=heading)) is None  # proven: the deviation itself counts
    assert "growing at 5/s" in str(_reason(_check(divergence=heading, proven=False)))


def test_a_foot_is_on_the_ground_if_any_of_its_contacts_is() -> None:
    contacts = (Contact.BOARD, Contact.GROUND, Contact.SWING, Contact.SWING, Contact.BOARD)
    feet = (0, 0, 1, 1, 2)  # two sites on each of the first two feet
    assert foot_support(contacts, feet, 4) == (
        Contact.GROUND,
        Contact.SWING,
        Contact.BOARD,
        Contact.SWING,  # no contact of its own: in the air
    )


def test_the_deck_axes_turn_with_its_yaw_and_its_sides_pair_the_feet() -> None:
    ahead = to_deck(math.pi / 2, np.array([[0.0, 1.0], [-1.0, 0.0]]))  # deck along world y
    np.testing.assert_allclose(ahead, [[1.0, 0.0], [0.0, 1.0]], atol=1e-12)
    assert (side_feet(4), side_feet(2), side_feet(3)) == (2, 0, 0)


class _Owner(Controller):
    def update(self, sensors: Any, command: Command) -> Any:  # pragma: no cover - unused
        raise NotImplementedError


def test_the_roll_is_extrapolated_at_its_rate_without_a_plan() -> None:
    settings = MpcSettings(horizon=4, dt=0.1)
    owner = _Owner(cast(Any, SimpleNamespace(name="r")), "skateboard")
    commands = CommandHorizon(owner, settings, 0.05, True, 1.0, False)
    commands.roll_horizon(Command(roll=0.0), 1.0)
    roll = commands.roll_horizon(Command(roll=0.1), 1.1)  # 1 rad/s
    np.testing.assert_allclose(roll, 0.1 + 1.0 * (0.05 + 0.1 * np.arange(5)))
    assert np.all(commands.yaw_rate_horizon(Command(yaw_rate=0.3), 1.1) == 0.3)
    # eq. (14): the turn a roll steers, -v sin(roll) / K at 0.5 m/s
    names = {"board_roll": 0}
    turn = commands.roll_turn(roll, 0.5, names)
    np.testing.assert_allclose(turn, -0.5 * np.sin(roll[:4]) / 1.0)
    owner.command_preview = lambda t: Command(velocity=2.0 * t, roll=0.2)
    assert commands.planned("velocity", np.array([1.0, 2.0])) == pytest.approx([2.0, 4.0])
    np.testing.assert_allclose(commands.roll_horizon(Command(roll=0.0), 1.2), 0.2)
    still = CommandHorizon(owner, settings, 0.0, False, None, False)
    assert not still.yaw_rate_horizon(Command(yaw_rate=0.3), 1.0).any()  # the lean turns it
    assert still.speed_command(Command(velocity=1.0), 1.0).velocity == 1.0  # no preview


def test_a_new_manoeuvre_ends_a_running_blend() -> None:
    blend = RepushBlend(cast(Any, None), cast(Any, None))
    blend._blend = cast(Any, object())  # a blend under way
    base: dict[str, Any] = dict.fromkeys(BuildInputs._fields)
    running = BuildInputs(**{**base, "began": False, "switched": False})
    assert blend.running(running)
    assert not blend.running(running._replace(began=True))


def test_the_turn_so_far_integrates_each_rate_until_the_next() -> None:
    turn = TurnSoFar()
    assert turn.advance(1.0, 0.5) == 0.0  # nothing before the first rate
    assert turn.advance(3.0, -1.0) == pytest.approx(1.0)  # 0.5 rad/s over 2 s
    assert turn.advance(3.5, 0.0) == pytest.approx(0.5)
    # the estimate's heading wraps at pi, the commanded turn does not: 2 pi is added back
    x0, reference = np.array([3.1 - 2.0 * math.pi, 0.3]), np.array([0.0, 0.0])
    turn.turned = 3.0
    np.testing.assert_allclose(turn.unwrapped(x0, reference, [0]), [3.1, 0.3])


@pytest.mark.parametrize(
    ("robot", "board"),
    [("cassie", "hovershoes"), ("cassie", "segway"), ("cyberdog2", "skateboard")],
)
def test_each_pair_file_stage_is_in_its_protocol_list(robot: str, board: str) -> None:
    """The rider builds a stage where its pair file names one, and none elsewhere."""
    from ridempc.mpc.rider import MpcRider
    from ridempc.robots import load_robot

    rider = MpcRider(load_robot(robot), board)
    stages = rider.pair.description.stages
    kinds = {type(stage).__name__ for stage in (*rider.drifts, *rider.shapers)}
    kinds |= {type(stage).__name__ for stage in (*rider.observers, *rider.wbc_observers)}
    named = {
        "RollDrift": stages.roll_observer,
        "SteadyDrift": stages.disturbance,
        "PayloadModels": stages.payload,
        "DropWatch": stages.drop,
        "DropFlight": stages.flight,
        "PushWatch": stages.impulse,
        "ShoeUpdate": stages.shoe_observer,
    }
    for kind, stage in named.items():
        assert (kind in kinds) == (stage is not None), kind
    assert (rider.stance_roll is not None) == (stages.stance is not None)
    assert rider.triggers[0] is plan_failed and rider.triggers[-1] is diverging
    assert [type(s).__name__ for s in rider.shapers[:4]] == [
        "Coasting",
        "RollCommand",
        "RepushBlend",
        "Turn",
    ]
    rider.close()
