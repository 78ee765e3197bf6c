"""The deck-roll stages (:mod:`ridempc.mpc.stages.deck_roll`) and the feet's targets
(:mod:`ridempc.mpc.stages.feet_targets`) alone, given known stances."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.mpc.stages.base import MpcTick
from ridempc.mpc.stages.deck_roll import DeckSides, RollDrift, StanceRoll, to_deck
from ridempc.mpc.stages.feet_targets import FeetTargets
from ridempc.mpc.swing import VELOCITY_STEP
from ridempc.trajopt.schedule import Contact

WEIGHT = 100.0  # [N] the rider's weight
SHARE = 0.2  # [-] the library's least share of the weight on the deck's feet
LEAST = SHARE * WEIGHT / 4  # [N] the least force of one of four feet


def _sides() -> DeckSides:
    force_index = np.arange(12).reshape(4, 3)  # per foot its (x, y, z) force inputs
    reference = SimpleNamespace(min_board_share=SHARE, force_index=force_index)
    return DeckSides(cast(Any, SimpleNamespace(reference=reference)), WEIGHT, side=2)


def _tick(forces: Any = (30.0, 30.0, 30.0, 30.0), yaw: float = 0.0, **fields: Any) -> MpcTick:
    """Four feet on the deck, two each side of its centre line (left: feet 0 and 1), the
    plan's vertical force on each ``forces`` [N]."""
    feet = np.array([[0.2, 0.1, 0.0], [-0.2, 0.1, 0.0], [0.2, -0.1, 0.0], [-0.2, -0.1, 0.0]])
    c, s = math.cos(yaw), math.sin(yaw)
    feet[:, :2] = feet[:, :2] @ np.array([[c, s], [-s, c]])  # the deck turned by ``yaw``
    first_input = np.zeros(12)
    first_input[[2, 5, 8, 11]] = forces
    estimate = SimpleNamespace(
        board=SimpleNamespace(yaw=yaw, roll=0.0),
        foot_position=feet,
        contact=np.ones(4, dtype=bool),
    )
    base: dict[str, Any] = {
        "estimate": estimate,
        "now": 1.1,
        "speed": 0.0,
        "balancing": True,
        "plan": SimpleNamespace(first_input=first_input),
        "plan_time": 1.0,
        "frame_turn": 0.0,
        "held": False,
        "diagnostics": {},
    }
    base.update(fields)
    return MpcTick(**base)


@pytest.mark.parametrize("yaw", [0.0, 2.0])
def test_a_side_is_light_when_both_its_feet_are_off_or_at_the_least_force(yaw: float) -> None:
    """Two feet on one fore-aft line cannot see the deck's roll: a side is light when both
    its feet (by their places across the deck, whatever its heading) are off the deck or
    planned within 1 N of the least force :math:`s\\,mg/4`; one light foot a side is not."""
    sides = _sides()
    assert sides.least_force() == pytest.approx(LEAST)
    assert not sides.one_side_light(_tick(yaw=yaw))
    assert sides.one_side_light(_tick((LEAST + 0.5, LEAST, 30.0, 30.0), yaw))
    assert sides.one_side_light(_tick((30.0, 30.0, LEAST, LEAST), yaw))
    assert not sides.one_side_light(_tick((LEAST, 30.0, LEAST, 30.0), yaw))
    lifted = _tick(yaw=yaw)
    lifted.estimate.contact[[2, 3]] = False
    assert sides.one_side_light(lifted)


class _Observer:
    def __init__(self) -> None:
        self.updates: list[tuple[float, bool]] = []
        self.resets = 0

    def update(self, x0: Any, plan: Any, share: float, hold: bool) -> float:
        self.updates.append((share, hold))
        return 0.3

    def drift(self, nx: int) -> np.ndarray:
        return np.ones(nx)

    def reset(self) -> None:
        self.resets += 1


def test_the_roll_drift_is_held_on_a_light_side_and_restarts_off_balance() -> None:
    """Balancing, the deck's torque is estimated at the plan's share of its step
    :math:`(t - t_0)/\\Delta t`, held while a side is light; a push-off (not balancing)
    restarts the observer and adds no drift."""
    observer = _Observer()
    source = RollDrift(cast(Any, observer), _sides(), dt=0.2)
    diagnostics: dict[str, float] = {}
    assert source.drift(_tick(diagnostics=diagnostics), np.zeros(3)) is not None
    source.drift(_tick((LEAST, LEAST, 30.0, 30.0)), np.zeros(3))
    assert observer.updates == [(pytest.approx(0.5), False), (pytest.approx(0.5), True)]
    assert diagnostics["roll_disturbance"] == 0.3
    assert source.drift(_tick(balancing=False), np.zeros(3)) is None and observer.resets == 1


class _Limit:
    def __init__(self) -> None:
        self.last = (-0.01, 0.01)
        self.asked: list[Any] = []
        self.resets = 0

    def bounds(self, places: Any, offset: Any, roll: float, dt: float, far: float) -> Any:
        self.asked.append((places, offset, dt, far))
        return -0.05, 0.04

    def reset(self) -> None:
        self.resets += 1


@pytest.mark.parametrize("yaw", [0.0, 1.0])
def test_the_commanded_roll_is_held_within_the_four_feets_stance(yaw: float) -> None:
    """With four feet on the deck the roll is held within the stance's bounds, from the
    feet's places and the centre of mass's about their centre in the deck's axes and the
    far side's least share :math:`2 f_{min} / mg`; with a foot off it, within the last
    bounds; off balance the limit restarts and the roll is as commanded."""
    limit = _Limit()
    com = np.array([0.01, 0.02, 0.3])
    stance = StanceRoll(cast(Any, limit), _sides(), lambda estimate: com)
    roll = np.array([-0.1, 0.0, 0.1])
    tick = _tick(yaw=yaw)
    np.testing.assert_array_equal(stance(roll, tick), [-0.05, 0.0, 0.04])
    places, offset, dt, far = limit.asked[0]
    feet = tick.estimate.foot_position[:, :2]
    np.testing.assert_allclose(places, to_deck(yaw, feet - feet.mean(axis=0)))
    np.testing.assert_allclose(places[0], [0.2, 0.1], atol=1e-12)  # front left, deck axes
    np.testing.assert_allclose(offset, to_deck(yaw, com[:2]))
    assert dt == pytest.approx(0.1) and far == pytest.approx(2.0 * LEAST / WEIGHT)
    lifted = _tick(yaw=yaw)
    lifted.estimate.contact[0] = False
    np.testing.assert_array_equal(stance(roll, lifted), [-0.01, 0.0, 0.01])
    np.testing.assert_array_equal(stance(roll, _tick(balancing=False)), roll)
    assert limit.resets == 1


def _feet_targets(plans_feet: bool) -> tuple[FeetTargets, list[Any]]:
    asked: list[Any] = []
    feet = SimpleNamespace(
        plans_feet=plans_feet,
        joint_angles=lambda state, q: np.full(3, state[0]),
        targets=lambda states, frame, board: (asked.append(states) or "swing", "swing rate"),
    )
    model = SimpleNamespace(foot_points=lambda q: "where they are")
    wbc = SimpleNamespace(motor_q=None, model=model)
    mpc = SimpleNamespace(reference=SimpleNamespace(states_at=lambda t: np.asarray(t)[:, None]))
    return FeetTargets(cast(Any, feet), cast(Any, wbc), cast(Any, mpc)), asked


def test_the_feet_stand_or_swing_as_scheduled() -> None:
    """A foot stands unless all its contacts swing; with no foot standing (a flight) all
    are held in contact for the QP; a lifted foot follows the reference's feet where the
    library plans them (read at ``t_ref`` and ``VELOCITY_STEP`` on), else holds where it is."""
    estimate = SimpleNamespace(boards=(), q=None)
    held, _ = _feet_targets(plans_feet=False)
    lifted = held((Contact.BOARD, Contact.SWING), 1.0, cast(Any, estimate), cast(Any, None))
    assert list(lifted.contact) == [True, False] and lifted.swing == "where they are"
    standing = held((Contact.BOARD, Contact.GROUND), 1.0, cast(Any, estimate), cast(Any, None))
    assert standing.contact.all() and standing.swing is None and standing.posture is None
    flying = held((Contact.SWING, Contact.SWING), 1.0, cast(Any, estimate), cast(Any, None))
    assert flying.contact.all()
    planned, asked = _feet_targets(plans_feet=True)
    out = planned((Contact.SWING, Contact.BOARD), 2.0, cast(Any, estimate), cast(Any, None))
    assert out.swing == "swing" and out.swing_velocity == "swing rate"
    np.testing.assert_allclose(asked[0][:, 0], [2.0, 2.0 + VELOCITY_STEP])
    np.testing.assert_array_equal(out.posture, np.full(3, 2.0))
