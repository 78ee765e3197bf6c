"""Cassie on the Hovershoes: lean-to-accelerate, stop and turn (:mod:`.ride_pair`)."""

from ridempc.trajopt.ride_pair import make_ride_pair

__all__ = ["PAIR"]

PAIR = make_ride_pair("cassie", "hovershoes", default_targets=(0.5, 1.0, 1.5))
