"""Offline trajectory optimisation (CasADi + IPOPT) for every robot-board pair.

One concept per module: :mod:`.kinematics` (forward kinematics from Pinocchio),
:mod:`.rotations`, :mod:`.rigid_body` (the SRBKM robot, eq. 1-3), :mod:`.rider` (the
simplified biped), :mod:`.skateboard` and :mod:`.platforms` (the boards' reduced models),
:mod:`.schedule` (contact schedules), :mod:`.problem` (the NLP's transcription, build and
solve), :mod:`.skate_problem` and :mod:`.ride_problem` (one NLP per kind of pair),
:mod:`.pairs` (the registry the library builder uses) and :mod:`.validation` (re-simulation).
"""

from ridempc.trajopt.pairs import EntrySpec, Pair, load_pair, pair_names
from ridempc.trajopt.problem import TrajectoryProblem, TrajectorySolution, solve_trajectory
from ridempc.trajopt.rigid_body import RigidBodyRobot, build_rigid_body_robot
from ridempc.trajopt.validation import Drift, resimulate

__all__ = [
    "Drift",
    "EntrySpec",
    "Pair",
    "RigidBodyRobot",
    "TrajectoryProblem",
    "TrajectorySolution",
    "build_rigid_body_robot",
    "load_pair",
    "pair_names",
    "resimulate",
    "solve_trajectory",
]
