"""The payload stage: the rider's estimated mass and centre of mass put into its models.

Every control tick the stance's loads are read (:class:`~ridempc.mpc.payload.PayloadEstimator`);
at each MPC tick the estimate over the last MPC step goes into the models the state map and
the whole-body QP read (their links' inertias), while the rider balances (holds or coasts;
held through a manoeuvre, whose accelerations move the centre of pressure off the centre of
mass), and its weight the MPC's vertical rate carries as a drift
(:class:`~ridempc.mpc.stages.base.DriftSource`); a
:class:`~ridempc.mpc.stages.base.TickObserver` and a drift source.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.estimation import EstimatedState
from ridempc.mpc.payload import PayloadEstimator
from ridempc.mpc.stages.base import ControlTick, MpcTick

__all__ = ["PayloadModels"]

Array = NDArray[np.float64]


class PayloadModels:
    """The payload's estimate read every tick and put into the models at each MPC tick.

    Args:
        payload: The estimator.
        models: The Pinocchio models whose link inertias carry the estimate (the map's and
            the whole-body QP's).
        com: The estimate's centre of mass [m], world frame (from the map's model).
        vz: The vertical rate's row in the MPC's state.
    """

    def __init__(
        self,
        payload: PayloadEstimator,
        models: Sequence[pin.Model],
        com: Callable[[EstimatedState], Array],
        vz: int,
    ) -> None:
        self.payload, self._models, self._com, self._vz = payload, tuple(models), com, vz

    def observe(self, tick: ControlTick) -> None:
        """One control tick's reading of the stance's loads [-] and the sensors."""
        sensors = tick.sensors
        contact = tick.estimate.contact
        self.payload.accumulate(tick.loads, contact, sensors.motor_torque, sensors.imu)

    def absorb(self, tick: MpcTick) -> None:
        """The estimate over the last MPC step (dropped unless balancing) into the models."""
        if not tick.balancing:
            self.payload.reset()
        payload = self.payload.update(tick.estimate.q, self._com(tick.estimate))
        for joint, inertia in enumerate(payload.inertias(self.payload.nominal_inertias)):
            for model in self._models:
                model.inertias[joint] = inertia
        tick.diagnostics.update(payload_kg=payload.mass)

    def drift(self, tick: MpcTick, x0: Array) -> Array | None:
        """The payload's weight on the vertical rate."""
        return self.payload.estimate.drift(len(x0), self._vz)
