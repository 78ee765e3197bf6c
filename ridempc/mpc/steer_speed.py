"""Whether the board rolls fast enough to steer, with a band against the speed's noise.

The deck's roll turns the board at :math:`\\omega = -v \\sin\\varphi / K_{board}` (eq. 14),
steered only above the least speed :math:`v_{min}`
(:data:`~ridempc.boards.skateboard.steering.MIN_SPEED`, 0.3 m/s): below it the roll that
turns the board grows without bound. A path follower asks :math:`\\omega \\propto v`, so the
roll it needs does not depend on the speed, but a board held near :math:`v_{min}` (a held
circle's re-pushes slow it to 0.25-0.35 m/s) crosses it with the estimate's noise from one
MPC tick to the next, and the steering roll jumped between 0 and the stance's 0.12 rad at the
MPC's 30 Hz (circle-hold seed 0, 15.5-16.9 s, the re-push's swing before the first handover).
Once steering, the rider keeps steering until the speed falls a noise band below
:math:`v_{min}`, at the roll :math:`v_{min}` asks for.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["NOISE_BAND", "SteerSpeed"]

# [m/s] twice the estimate's speed error (its velocity RMSE 0.03 m/s on the held circles and
# the library's circle): a board this far below the least speed is below it, not noise
NOISE_BAND: float = 0.06


@dataclass
class SteerSpeed:
    """The speed [m/s] to steer at: the board's, held at ``min_speed`` while it has dropped
    less than ``band`` below it since steering began; 0 (no steering) otherwise.

    Attributes:
        min_speed: :math:`v_{min}` [m/s].
        band: The noise band [m/s].
        steering: Whether the last speed steered.
    """

    min_speed: float
    band: float = NOISE_BAND
    steering: bool = False

    def __call__(self, speed: float) -> float:
        """The speed to steer at for the board's ``speed`` [m/s] (its magnitude)."""
        v = abs(speed)
        if v >= self.min_speed:
            self.steering = True
            return speed
        if self.steering and v >= self.min_speed - self.band:
            return self.min_speed if speed >= 0.0 else -self.min_speed
        self.steering = False
        return 0.0
