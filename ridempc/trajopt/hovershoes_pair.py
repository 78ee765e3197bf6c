"""Cassie on the Hovershoes: lean-to-accelerate, stop and turn (:mod:`.ride_pair`).

The shoes' speed changes take 0.4 s plus 0.8 s per m/s (0.6 to 0.9 m/s^2 for 0.5 to
1.5 m/s): on RideOptions' 1 s plus 2 s per m/s, the MPC rider's velocity steps of
0.5/1.0/1.5 m/s had an RMSE of 0.173 m/s, 97 % of its squared error within 4 s of each
step, against the PD baseline's 0.114 (seed 0); on these, 0.139 (seed 1: 0.168 -> 0.136).
Faster still (0.3 s plus 0.6 s per m/s, settling 0.3 s) gave 0.125 but fell at 1.5 m/s.
With the MPC's terminal factor of 30 and its start speed (:class:`~ridempc.mpc.pairs.MpcPair`)
these give 0.1102; the faster ones fell at 23.81 s at that factor, and at 20 gave 0.1119.
Tracked perfectly, from the start speed, these references alone would score 0.078 m/s and
the faster ones 0.066.
"""

from ridempc.trajopt.ride_pair import make_ride_pair

__all__ = ["PAIR", "SPEED_CHANGES"]

# The speed changes' timing (RideOptions' fields), the Segway's too.
SPEED_CHANGES: dict[str, float] = {"seconds_per_speed": 0.8, "manoeuvre_base": 0.4}

PAIR = make_ride_pair(
    "cassie",
    "hovershoes",
    default_targets=(0.5, 1.0, 1.5),
    options=SPEED_CHANGES,
)
