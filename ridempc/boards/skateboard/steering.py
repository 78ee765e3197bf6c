"""Steering the skateboard by its deck roll: a yaw-rate command to a roll reference.

The trucks' geometry (skateboard paper, eqs. 11-14, :mod:`.reduced`) turns a deck rolled by
:math:`\\varphi` at forward speed :math:`v` at :math:`\\omega = -v \\sin\\varphi / K_{board}`.
Inverted, a wanted yaw rate :math:`\\omega^*` [rad/s] asks for the roll

.. math:: \\varphi^* = -\\arcsin\\left(\\frac{\\omega^* K_{board}}{v}\\right)

which the rider can lean into only within the roll its four-leg stance holds
(:data:`STANCE_ROLL`, the paper's largest) and only while the board rolls: at
:math:`v \\to 0` the roll that turns it grows without bound and the speed read from the
odometry is mostly noise (:data:`MIN_SPEED`). A turn of radius :math:`R` asks for
:math:`\\sin\\varphi = K_{board} / R` at any speed, so the tightest turn is
:math:`R_{min} = K_{board} / \\sin\\varphi_{max}`.

One map for every rider (the PD baseline and the MPC); the scenario's commands are checked
against the same limits before a ride (:meth:`RollSteering.check_command`).
"""

from __future__ import annotations

import math

from pydantic import Field

from ridempc.boards.skateboard.parameters import SkateboardParameters
from ridempc.boards.skateboard.reduced import steer_gain
from ridempc.errors import ConfigError
from ridempc.units import CheckedModel, Positive, Real

__all__ = ["MIN_SPEED", "STANCE_ROLL", "RollSteering"]

# [rad] the largest deck roll the dog held in four-leg balancing (skateboard paper, Sec. VI-A:
# "the maximum angle of phi_B is about 0.12 rad"); beyond it the far feet unload.
STANCE_ROLL: float = 0.12
# [m/s] below this the board is taken as not rolling: the VIO's speed noise (a few cm/s) is
# then a tenth of the speed, and a 0.2 rad/s turn would need more than STANCE_ROLL below 0.35.
MIN_SPEED: float = 0.3


class RollSteering(CheckedModel):
    """The yaw-rate to deck-roll map of one skateboard, within what the stance holds.

    Attributes:
        gain: :math:`1 / K_{board} = (\\cot\\gamma_f + \\cot\\gamma_r) / L` [1/m].
        max_roll: Largest steering roll the rider holds [rad].
        min_speed: Least forward speed at which a yaw rate is steered [m/s].
    """

    gain: Positive
    max_roll: Real = Field(STANCE_ROLL, gt=0.0, lt=0.5)
    min_speed: Positive = MIN_SPEED

    @classmethod
    def of(cls, params: SkateboardParameters, **limits: float) -> RollSteering:
        """The map of a board: its identified gain (the geometric one before
        identification), with the default limits unless given."""
        gain = params.reduced.steer_gain if params.reduced is not None else steer_gain(params)
        return cls(gain=gain, **limits)

    @property
    def min_radius(self) -> float:
        """Tightest turn the stance can lean into, :math:`K_{board} / \\sin\\varphi_{max}` [m]."""
        return 1.0 / (self.gain * math.sin(self.max_roll))

    def max_yaw_rate(self, speed: float) -> float:
        """Largest yaw rate steered at ``speed`` [m/s]: :math:`|v| \\sin\\varphi_{max} /
        K_{board}` [rad/s]; zero below the least speed."""
        if abs(speed) < self.min_speed:
            return 0.0
        return self.gain * abs(speed) * math.sin(self.max_roll)

    def roll(self, yaw_rate: float, speed: float) -> float:
        """Deck roll that turns the board at ``yaw_rate`` [rad/s] (positive left) at
        ``speed`` [m/s], eq. (14) inverted, clipped to :math:`\\pm` ``max_roll``; zero
        below the least speed [rad]. Positive roll lowers the right edge and turns right."""
        if abs(speed) < self.min_speed or yaw_rate == 0.0:
            return 0.0
        ratio = yaw_rate / (self.gain * speed)
        bound = math.sin(self.max_roll)
        return -math.asin(max(-bound, min(bound, ratio)))

    def check_command(self, yaw_rate: float, speed: float, where: str) -> None:
        """Refuse a commanded yaw rate the board cannot steer at the commanded speed.

        Args:
            yaw_rate: Commanded yaw rate [rad/s].
            speed: Commanded forward speed at that time [m/s].
            where: What the command is called in the user's input (a file and field).

        Raises:
            ConfigError: A turn below the least speed, or one that needs a roll beyond
                ``max_roll``; the message names ``where``, the value and what is allowed.
        """
        if yaw_rate == 0.0:
            return
        if abs(speed) < self.min_speed:
            raise ConfigError(
                f"{where}: yaw_rate {yaw_rate:g} rad/s at velocity {speed:g} m/s; allowed: "
                f"a yaw rate only at |velocity| >= {self.min_speed:g} m/s (the skateboard "
                "steers by its deck roll, eq. 14)"
            )
        limit = self.max_yaw_rate(speed)
        if abs(yaw_rate) > limit + 1e-9:
            raise ConfigError(
                f"{where}: yaw_rate {yaw_rate:g} rad/s at velocity {speed:g} m/s; allowed: "
                f"|yaw_rate| <= {limit:.3f} rad/s (a deck roll within {self.max_roll:g} rad)"
            )

    def check_radius(self, radius: float, where: str) -> None:
        """Refuse a path turning tighter than :attr:`min_radius`.

        Raises:
            ConfigError: ``radius`` [m] below the tightest turn; the message names ``where``.
        """
        if abs(radius) < self.min_radius:
            raise ConfigError(
                f"{where}: radius {radius:g} m; allowed: at least {self.min_radius:.2f} m "
                f"(a deck roll within {self.max_roll:g} rad)"
            )
