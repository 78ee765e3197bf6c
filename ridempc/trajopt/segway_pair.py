"""Cassie on the Segway: lean-to-accelerate, stop and turn (:mod:`.ride_pair`)."""

from ridempc.trajopt.ride_pair import make_ride_pair

__all__ = ["PAIR"]

PAIR = make_ride_pair("cassie", "segway", default_targets=(0.5, 1.0, 2.0, 3.0, 4.0))
