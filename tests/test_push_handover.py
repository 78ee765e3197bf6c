"""A slow board's re-push stroke is not handed to the balancing backup for its deviation
alone (:mod:`ridempc.mpc.push_handover`)."""

from __future__ import annotations

from ridempc.mpc.push_handover import deviation_deferred
from ridempc.trajopt.schedule import Contact

B, G, S = Contact.BOARD, Contact.GROUND, Contact.SWING
START = 0.5  # [m/s] the stride's rolling start


def test_a_slow_boards_re_push_with_a_foot_off_the_deck_rides_its_stroke_out() -> None:
    assert deviation_deferred(True, (B, B, G, B), 0.3, START)  # pushing on the ground
    assert deviation_deferred(True, (B, B, B, S), 0.3, START)  # swinging back to the deck


def test_a_board_at_its_strides_rolling_start_is_judged_as_before() -> None:
    assert not deviation_deferred(True, (B, B, B, S), START, START)
    assert not deviation_deferred(True, (B, B, B, S), 0.7, START)


def test_every_foot_on_the_deck_is_judged_as_before() -> None:
    assert not deviation_deferred(True, (B, B, B, B), 0.3, START)


def test_other_manoeuvres_and_a_rider_before_its_first_plan_are_judged_as_before() -> None:
    assert not deviation_deferred(False, (B, B, G, B), 0.3, START)  # the push-off from rest
    assert not deviation_deferred(True, None, 0.3, START)
