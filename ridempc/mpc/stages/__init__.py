"""The rider's stages, one protocol each (:mod:`ridempc.mpc.stages.base`), that
:class:`~ridempc.mpc.rider.MpcRider` loops over."""

from ridempc.mpc.stages.base import DriftSource, MpcTick, ProblemShaper

__all__ = ["DriftSource", "MpcTick", "ProblemShaper"]
