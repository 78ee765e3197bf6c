"""The rider's mass weighed by its own vertical motion: the MPC's prediction error of the
centre of mass's vertical velocity, read as the weight the model is missing.

The MPC's vertical rate is :math:`\\dot v_z = \\sum_i f_{z,i} / m_0 - g + d_z` (:math:`m_0`
[kg] the model's mass, :math:`f_{z,i}` [N] the planned contact forces, :math:`d_z` [m/s^2]
the drift the payload puts there, :meth:`~ridempc.mpc.payload.PayloadEstimate.drift`). A
rider of mass :math:`m = m_0 + \\Delta m` given those forces accelerates at
:math:`\\sum_i f_{z,i} / m - g`: for forces near her weight the difference is
:math:`-g\\,(\\Delta m - \\Delta\\hat m) / m_0`, a constant error of the plan's vertical
rate that the offset-free observer over the vertical row
(:class:`~ridempc.mpc.disturbance.DisturbanceObserver`, the one-step prediction error of
the last plan) integrates to :math:`\\hat d_z = -g\\, \\Delta\\hat m / m_0`, so

.. math:: \\Delta\\hat m = -m_0\\, \\hat d_z / g.

Nothing here reads the feet's loads: where the board holds the feet in a crouch the load
signal's calibration fails (on the Segway it reads 1.1-1.3x the true load, growing with the
crouch; docs/tuning.md), but the centre of mass's vertical velocity comes from the
estimator's base velocity and the joints, the same state the MPC tracks. What the estimate
absorbs is every constant vertical error of the model (the legs' springs' sag, the
whole-body QP's force tracking), read as a mass: the whole-body controller then carries it
too, so its forces and the plan's agree.

The estimate is held while the plan is not followed (the backup rides, a solve is under
way) and through a manoeuvre (its accelerations are the plan's, and a fast start's plan is
followed less closely): only a balancing rider's residual is her weight.

A pair weighs its rider so with ``[stages.payload] mass_from = "prediction"``; none does yet:
on the Segway the estimate comes too late for the MPC riding alone, whose rides with a
payload are decided in the first 0.05-0.2 s (docs/tuning.md, "The Segway's payload",
session 11).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.gravity import GRAVITY
from ridempc.mpc.disturbance import DisturbanceObserver
from ridempc.mpc.stages.base import MpcTick

__all__ = ["MASS_BOUND", "TIME_CONSTANT_S", "VerticalWeight"]

Array = NDArray[np.float64]
# [s] the observer's time constant: above the balance's own time sqrt(h/g) ~ 0.3 s, since
# one MPC step's residual swings by 5-6 m/s^2 (half the weight) with the rider's vertical
# sway on her sprung legs, and a faster estimate passes that swing to the plan.
TIME_CONSTANT_S: float = 0.4
# [-] the largest payload read, as a fraction of the model's mass: the sweeps' payloads reach
# 30 %; a larger residual is a fall or a push, which the estimate must not wind up on.
MASS_BOUND: float = 0.4


class VerticalWeight:
    """The payload's mass from the MPC's vertical prediction error (module docstring).

    Args:
        vz: The vertical velocity's row in the MPC's state.
        model_mass: :math:`m_0` [kg].
        dt: The MPC's step [s].
        time_constant: The observer's :math:`\\tau` [s].
    """

    def __init__(
        self, vz: int, model_mass: float, dt: float, time_constant: float = TIME_CONSTANT_S
    ) -> None:
        self.observer = DisturbanceObserver(
            (vz,), (False,), time_constant, MASS_BOUND * GRAVITY, 1.0
        )
        self.model_mass, self._dt = model_mass, dt

    @property
    def mass(self) -> float:
        """:math:`\\Delta\\hat m` [kg], the rider's mass beyond the model's."""
        return -self.model_mass * float(self.observer.estimate[0]) / GRAVITY

    def update(self, tick: MpcTick, x0: Array) -> float:
        """One MPC tick's update from the last plan's prediction of ``x0`` (the mapped
        state); held while the plan is not followed, the rider does not balance, or a foot
        is off contact (a landing's impact is no weight).

        Returns:
            :math:`\\Delta\\hat m` [kg].
        """
        elapsed = tick.now - tick.plan_time
        standing = bool(np.all(tick.estimate.contact))
        hold = tick.held or not tick.balancing or not standing
        self.observer.update(x0, tick.plan, tick.now, elapsed, self._dt, tick.frame_turn, hold)
        return self.mass
