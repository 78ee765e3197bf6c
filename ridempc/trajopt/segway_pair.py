"""Cassie on the Segway: lean-to-accelerate, stop and turn (:mod:`.ride_pair`).

The speed changes take 0.4 s plus 0.8 s per m/s, as the Hovershoes' (3.6 s from 4 m/s to
rest). On RideOptions' 1 s plus 2 s per m/s (9 s for the same stop) the MPC rider lagged
each 1 m/s step of velocity-steps by about 2 s and was still riding at 3.8 m/s a second
after the command had come down to 2.7 m/s: velocity RMSE 0.938 m/s against the PD
baseline's 0.399 (seed 0); on these, 0.408. The circle's speed RMSE went 0.158 -> 0.015
m/s; push, offset-start and yaw-steps rode as before (seed 0).
The grid is 0.0125 s, half RideOptions': on 0.025 s these faster entries were up to 0.012
(state units) from an RK45 re-simulation over one interval, on 0.0125 s 0.0016.
"""

from ridempc.trajopt.hovershoes_pair import SPEED_CHANGES
from ridempc.trajopt.ride_pair import make_ride_pair

__all__ = ["PAIR"]

PAIR = make_ride_pair(
    "cassie",
    "segway",
    default_targets=(0.5, 1.0, 2.0, 3.0, 4.0),
    options={**SPEED_CHANGES, "dt": 0.0125},
)
