"""A re-push's stroke is not handed to the balancing backup for its deviation alone
(:mod:`ridempc.mpc.push_handover`)."""

from __future__ import annotations

from ridempc.mpc.push_handover import deviation_deferred
from ridempc.trajopt.schedule import Contact

B, G, S = Contact.BOARD, Contact.GROUND, Contact.SWING


def test_a_re_push_with_a_foot_off_the_deck_rides_its_stroke_out() -> None:
    assert deviation_deferred(True, (B, B, G, B))  # the foot pushing on the ground
    assert deviation_deferred(True, (B, B, B, S))  # the foot swinging back to the deck


def test_every_foot_on_the_deck_is_judged_as_before() -> None:
    assert not deviation_deferred(True, (B, B, B, B))


def test_other_manoeuvres_and_a_rider_before_its_first_plan_are_judged_as_before() -> None:
    assert not deviation_deferred(False, (B, B, G, B))  # the push-off from rest
    assert not deviation_deferred(True, None)
