"""The 30 Hz linear time-varying MPC of the skateboard paper (Sec. V-B, eq. 17-19), for any
robot-board pair with a motion library.

A pipeline of small modules: :mod:`.reference` (the library trajectory for a command and
its contact schedule), :mod:`.problem` (linearisation at the estimate and the checked
:class:`MpcProblem`), :mod:`.discretisation` (zero-order hold), :mod:`.friction` (friction
pyramids in the contacts' surface frames), :mod:`.weights` (Q and R), :mod:`.qp` (the
sparse QP built once and updated in place, OSQP), :mod:`.plan` (what a solve returns),
:mod:`.pairs` (each pair's surfaces and limits) and :mod:`.controller` (all of it at 30 Hz).
"""

from ridempc.mpc.controller import LinearMpc, MpcSettings
from ridempc.mpc.discretisation import zero_order_hold
from ridempc.mpc.friction import force_bounds, friction_pyramids, pyramid_pattern
from ridempc.mpc.pairs import MpcPair, load_mpc_pair, mpc_pair_names, surface_rotations
from ridempc.mpc.plan import Plan, shift_plan
from ridempc.mpc.problem import (
    MPC_STEP,
    LinearisedDynamics,
    LinearModel,
    MpcProblem,
    build_linear_model,
    linearize,
)
from ridempc.mpc.qp import MpcQP, QPStructure, SolveRecord
from ridempc.mpc.reference import (
    MotionReference,
    ReferenceWindow,
    reference_from_entry,
    select_reference,
    steady_riding,
)
from ridempc.mpc.weights import bryson_weights

__all__ = [
    "MPC_STEP",
    "LinearMpc",
    "LinearModel",
    "LinearisedDynamics",
    "MotionReference",
    "MpcPair",
    "MpcProblem",
    "MpcQP",
    "MpcSettings",
    "Plan",
    "QPStructure",
    "ReferenceWindow",
    "SolveRecord",
    "build_linear_model",
    "bryson_weights",
    "force_bounds",
    "friction_pyramids",
    "linearize",
    "load_mpc_pair",
    "mpc_pair_names",
    "pyramid_pattern",
    "reference_from_entry",
    "select_reference",
    "shift_plan",
    "steady_riding",
    "surface_rotations",
    "zero_order_hold",
]
