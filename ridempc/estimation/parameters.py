"""The estimator's noise model and thresholds: :class:`EstimatorParameters`.

Standard deviations are the filter's *belief* about its inputs, tuned for the simulated
sensors of :class:`~ridempc.sim.sensors.SensorNoise` with margin for what the linear model
leaves out (foot roll and slip, the IMU's orientation error tilting gravity, the VIO's
latency). Process noises are densities: a state with density :math:`\\sigma` gains
:math:`\\sigma^2 \\Delta t` of variance per step.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

__all__ = ["EstimatorParameters"]


class EstimatorParameters(BaseModel):
    """Checked, immutable settings of :class:`~ridempc.estimation.StateEstimator`."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    accel_std: float = Field(
        0.1,
        gt=0,
        description="[m/s^2/sqrt(Hz)] white acceleration noise of the IMU-point process model "
        "(the simulated accelerometer has white noise and no bias; raise it for a biased one)",
    )
    foot_position_std: float = Field(
        0.002, gt=0, description="[m/sqrt(s)] stance-foot position random walk (rolling, sinking)"
    )
    swing_position_std: float = Field(
        3.0, gt=0, description="[m/sqrt(s)] swing-foot position random walk: the foot moves freely"
    )
    support_accel_std: float = Field(
        2.0,
        gt=0,
        description="[m/s^2/sqrt(Hz)] random walk of the velocity of a board under a foot",
    )
    static_support_std: float = Field(
        0.01, gt=0, description="[m/s] stationary std of the ground's velocity under a foot (slip)"
    )
    support_correlation_time: float = Field(
        0.05, gt=0, description="[s] how long a foot's slip on the ground persists"
    )
    kinematic_position_std: float = Field(
        0.003, gt=0, description="[m] foot position relative to the IMU from the encoders"
    )
    kinematic_velocity_std: float = Field(
        0.03, gt=0, description="[m/s] foot velocity relative to the IMU from the encoders"
    )
    velocity_gate: float = Field(
        16.27,
        gt=0,
        description="[-] chi-square (3 DoF) above which a stance foot's velocity is an outlier "
        "(16.27: probability 0.001 for a consistent measurement)",
    )
    vio_position_std: float = Field(0.012, gt=0, description="[m] VIO base position")
    vio_velocity_std: float = Field(0.03, gt=0, description="[m/s] VIO base velocity")
    history: float = Field(
        1.0, gt=0, le=10.0, description="[s] state history kept to meet delayed VIO samples"
    )
    initial_position_std: float = Field(
        1.0, gt=0, description="[m] prior on the horizontal position before the first VIO sample"
    )
    initial_height_std: float = Field(
        0.5, gt=0, description="[m] prior on the height (feet taken on a support at z = 0)"
    )
    initial_velocity_std: float = Field(
        0.02, gt=0, description="[m/s] prior on the velocity (the first packet finds it at rest)"
    )
    contact_method: Literal["auto", "spring", "torque"] = Field(
        "auto",
        description="load signal of contact detection: spring deflection, joint torques, or "
        "auto (springs where every foot's chain has a measured spring)",
    )
    contact_on: float = Field(
        0.3, gt=0, description="[-] load, as a fraction of the standing load, to enter contact"
    )
    contact_off: float = Field(
        0.15, ge=0, description="[-] load fraction below which a foot leaves contact"
    )

    @model_validator(mode="after")
    def _hysteresis(self) -> EstimatorParameters:
        if self.contact_off >= self.contact_on:
            raise ValueError("contact_off must be below contact_on (hysteresis)")
        return self
