"""The payload stage: the rider's estimated mass and centre of mass put into its models.

Every control tick the stance's loads are read (:class:`~ridempc.mpc.payload.PayloadEstimator`);
at each MPC tick the estimate over the last MPC step goes into the models the state map and
the whole-body QP read (their links' inertias), while the rider balances (holds or coasts;
held through a manoeuvre, whose accelerations move the centre of pressure off the centre of
mass), and its weight the MPC's vertical rate carries as a drift
(:class:`~ridempc.mpc.stages.base.DriftSource`); a
:class:`~ridempc.mpc.stages.base.TickObserver` and a drift source. With a
:class:`~ridempc.mpc.vertical_weight.VerticalWeight` the mass is weighed by the MPC's own
vertical prediction error instead of the feet's loads (the pair's ``[stages.payload]
mass_from = "prediction"``), updated with the drift and in the models from the next MPC tick;
with a :class:`~ridempc.mpc.start_weight.StartWeight` it is weighed once, at the first MPC
tick, before the first plan (``mass_from = "start"``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ridempc.estimation import EstimatedState
from ridempc.mpc.payload import PayloadEstimator
from ridempc.mpc.stages.base import ControlTick, MpcTick
from ridempc.mpc.start_weight import StartWeight
from ridempc.mpc.vertical_weight import VerticalWeight
from ridempc.pair_description import PayloadStage

__all__ = ["PayloadModels", "start_weight", "weighed"]

Array = NDArray[np.float64]


def weighed(
    stage: PayloadStage | None, vz: int, payload: PayloadEstimator | None, dt: float
) -> VerticalWeight | None:
    """The mass weighed by the MPC's vertical prediction error, if the pair's payload stage
    asks for it (``mass_from = "prediction"``), for the vertical rate's row ``vz`` and the
    MPC's step ``dt`` [s]."""
    if stage is None or payload is None or stage.mass_from != "prediction":
        return None
    return VerticalWeight(vz, payload.mass0, dt)


def start_weight(stage: PayloadStage | None) -> StartWeight | None:
    """The mass weighed at the ride's first tick, if the pair's payload stage asks for it
    (``mass_from = "start"``, calibrated by its ``start_reading``)."""
    if stage is None or stage.start_reading is None:
        return None
    return StartWeight(float(stage.start_reading))


class PayloadModels:
    """The payload's estimate read every tick and put into the models at each MPC tick.

    Args:
        payload: The estimator.
        models: The Pinocchio models whose link inertias carry the estimate (the map's and
            the whole-body QP's).
        com: The estimate's centre of mass [m], world frame (from the map's model).
        vz: The vertical rate's row in the MPC's state.
        weight: The mass weighed by the vertical prediction error, or None (the loads').
        start: The mass weighed at the ride's first tick, or None.
    """

    def __init__(
        self,
        payload: PayloadEstimator,
        models: Sequence[pin.Model],
        com: Callable[[EstimatedState], Array],
        vz: int,
        weight: VerticalWeight | None = None,
        start: StartWeight | None = None,
    ) -> None:
        self.payload, self._models, self._com, self._vz = payload, tuple(models), com, vz
        self.weight, self.start = weight, start
        self._open_loop = False  # the backup rode the last control tick: no loop closed

    def observe(self, tick: ControlTick) -> None:
        """One control tick's reading of the stance's loads [-] and the sensors."""
        sensors = tick.sensors
        contact = tick.estimate.contact
        self.payload.accumulate(tick.loads, contact, sensors.motor_torque, sensors.imu)
        self._open_loop = tick.on_backup

    def absorb(self, tick: MpcTick) -> None:
        """The estimate over the last MPC step (dropped unless balancing) into the models:
        while the backup rides, the running mean of the readings
        (:meth:`~ridempc.mpc.payload.PayloadEstimator.update`'s ``open_loop``); weighed
        first by the start's weighing, if any and not yet done."""
        if self.start is not None:
            self.start.weigh(self.payload)
        if not tick.balancing:
            self.payload.reset()
        estimate = tick.estimate
        payload = self.payload.update(
            estimate.q, self._com(estimate), estimate.v, open_loop=self._open_loop
        )
        for joint, inertia in enumerate(payload.inertias(self.payload.nominal_inertias)):
            for model in self._models:
                model.inertias[joint] = inertia
        tick.diagnostics.update(payload_kg=payload.mass)

    def drift(self, tick: MpcTick, x0: Array) -> Array | None:
        """The payload's weight on the vertical rate (first weighed, with a
        :class:`~ridempc.mpc.vertical_weight.VerticalWeight`)."""
        if self.weight is not None:
            self.payload.weigh(self.weight.update(tick, x0))
        return self.payload.estimate.drift(len(x0), self._vz)
