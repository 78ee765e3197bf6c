"""State estimation for the riders (500 Hz): IMU attitude, encoders, leg odometry with VIO.

:class:`StateEstimator` turns each :class:`~ridempc.sim.sensors.SensorPacket` into an
:class:`EstimatedState`; see :mod:`ridempc.estimation.estimator` for the pipeline and
:mod:`ridempc.estimation.leg_odometry` for the filter.
"""

from ridempc.estimation.board import estimate_board
from ridempc.estimation.estimator import StateEstimator
from ridempc.estimation.parameters import EstimatorParameters
from ridempc.estimation.state import BoardEstimate, EstimatedState

__all__ = [
    "BoardEstimate",
    "EstimatedState",
    "EstimatorParameters",
    "StateEstimator",
    "estimate_board",
]
