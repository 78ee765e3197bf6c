"""The 500 Hz whole-body controller: a QP on accelerations, contact forces and torques.

:class:`WholeBodyController` turns an :class:`~ridempc.estimation.EstimatedState` and the
MPC's :class:`WbcTargets` into a :class:`WbcOutput` (motor torques and joint targets) by one
OSQP solve; :func:`to_motor_command` hands it to the motor drivers. The pieces, one per
module: :mod:`~ridempc.wbc.layout` (the decision vector), :mod:`~ridempc.wbc.model`
(Pinocchio terms), :mod:`~ridempc.wbc.contacts` (supports), :mod:`~ridempc.wbc.tasks`
(objective), :mod:`~ridempc.wbc.constraints`, :mod:`~ridempc.wbc.qp` (build and solve),
:mod:`~ridempc.wbc.settings`, :mod:`~ridempc.wbc.targets`, :mod:`~ridempc.wbc.controller`.
"""

from ridempc.wbc.controller import TRACKED_POINTS, WholeBodyController, to_motor_command
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.model import ModelTerms, WholeBodyModel
from ridempc.wbc.qp import QpProblem, QpSolution, WbcFailed, WholeBodyQP
from ridempc.wbc.settings import TrackingGains, WbcSettings
from ridempc.wbc.targets import WbcOutput, WbcTargets

__all__ = [
    "TRACKED_POINTS",
    "DecisionLayout",
    "ModelTerms",
    "QpProblem",
    "QpSolution",
    "TrackingGains",
    "WbcFailed",
    "WbcOutput",
    "WbcSettings",
    "WbcTargets",
    "WholeBodyController",
    "WholeBodyModel",
    "WholeBodyQP",
    "to_motor_command",
]
