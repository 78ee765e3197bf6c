"""A drop ridden by the whole-body QP itself: the feet follow the falling platforms down.

Rolling off a step, the platforms fall away from under the rider's feet
(:class:`~ridempc.mpc.drop.DropDetector`). The MPC's reduced model has no flight phase: its
plan keeps every foot pressing, which pushes the falling platforms down at 1-3.5 g and
pitches them. While the drop lasts, the whole-body QP is told instead that no foot stands:
no foot force is planned, and each foot follows its platform down as a swing foot,

.. math:: p_i^*(t) = p_{base}(t) + (p_i - p_{base})(t_0) - e(t)\\,\\hat z, \\quad
          \\ddot p_i^* = -g\\,\\hat z, \\quad e(t) = \\min(v_e (t - t_0), e_{max})

held where it was under the base when the loads went (the rider and her light platforms
fall together) and reaching down at :math:`v_e` by up to :math:`e_{max}` [m], so that the
legs follow the platforms down and land with their stroke ahead of them, as the PD's legs
do (:mod:`ridempc.baselines.hovershoe_flight`). Once every foot has stopped sinking
(slower than the drop's :data:`~ridempc.mpc.drop.SINK_SPEED`) for ``LAND_TICKS`` ticks, the
platforms have landed, and the QP takes the MPC's plan back: its contact forces absorb the
fall over the legs' stroke. The loads cannot tell the landing: a foot reaching after its
platform presses on it and reads as loaded long before the platform lands. A flight longer
than ``LONGEST_S`` is a fall no step explains, and is the drop's handover to the backup law.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation.state import EstimatedState
from ridempc.gravity import GRAVITY
from ridempc.mpc.drop import SINK_SPEED
from ridempc.mpc.stages.base import ControlTick
from ridempc.mpc.stages.feet_targets import FootTargets
from ridempc.mpc.stages.triggers import DropWatch, HandoverCheck

__all__ = [
    "EXTEND_SPEED",
    "LAND_TICKS",
    "LONGEST_S",
    "MAX_EXTENSION",
    "DropFlight",
]

Array = NDArray[np.float64]

# [m/s] the legs' reach after the falling platforms, the default (a pair sets its own in
# ``[stages.flight]``; the Hovershoes PD's ``[flight] extend_speed`` is the same):
# the fall's speed 0.1 s after the edge, so the feet keep up with their platforms.
EXTEND_SPEED: float = 1.0
# [m] the longest reach, the default (``[stages.flight] max_extension``): the legs' stroke from the
# riding posture to near full length, deeper than the highest step a board rolls down.
MAX_EXTENSION: float = 0.1
# [ticks] in a row, 10 ms at 500 Hz: the feet stopped by their landed platforms, not a
# velocity estimate's one-tick swing.
LAND_TICKS: int = 5
# [s] the longest drop ridden: free fall through 2 wheel radii of the largest board
# (0.1 m, 0.14 s) and the legs' reach after it; a longer one is no step.
LONGEST_S: float = 0.3


class DropFlight:
    """The flight between a drop and the landing, and the feet's swing targets through it.

    A stage of the rider (:mod:`~ridempc.mpc.stages.base`): a tick observer after the drop's
    watch (``observe``: a flight starts on its drop while the MPC rides), the drop's
    handover trigger in the watch's place (``__call__``: only a flight longer than any
    step's), and, while ``flying``, the feet's targets (``feet``: no foot in contact, each
    swinging after its platform); the rider asks no later trigger while it flies.

    Attributes:
        starts: When each flight of the ride began [s] (``summary.json``'s ``flights_s``).
        landed: When the last flight landed [s] (None: none yet), for
            :mod:`~ridempc.mpc.landing`.
        depth: How far the last flight fell [m] (None: none landed yet): the feet's mean
            height at the drop less theirs at the landing, both from the estimate (the IMU,
            the VIO and the legs' kinematics), so a step's height as the rider measured it.
        depths: Each landed flight's ``depth`` [m] (``summary.json``'s ``flight_depths_m``).

    Args:
        watch: The drop's watch, observed before this stage each tick (None: ``update``
            is called directly).
        extend_speed: How fast the feet reach down after the platforms [m/s].
        max_extension: How far they reach at most [m].
    """

    def __init__(
        self,
        watch: DropWatch | None = None,
        extend_speed: float = EXTEND_SPEED,
        max_extension: float = MAX_EXTENSION,
    ) -> None:
        if not extend_speed > 0.0 or not max_extension > 0.0:
            raise ValueError(
                f"flight: extend_speed {extend_speed} and max_extension {max_extension} must be > 0"
            )
        self.watch = watch
        self.extend_speed = extend_speed
        self.max_extension = max_extension
        self._now = 0.0  # [s] the last tick observed
        self._start: float | None = None
        self._offsets = np.zeros((0, 3))  # [m] each foot from the base, at the drop
        self._height = 0.0  # [m] the feet's mean height at the drop
        self._sank = False  # whether a foot has sunk faster than SINK_SPEED in this flight
        self._stopped = 0
        self.starts: list[float] = []  # [s] when each flight of the ride began
        self.landed: float | None = None  # [s] when the last flight landed
        self.depth: float | None = None  # [m] how far the last flight fell
        self.depths: list[float] = []  # [m] how far each landed flight fell

    @property
    def flying(self) -> bool:
        """Whether a drop is being ridden (from its detection to the landing)."""
        return self._start is not None

    def reset(self) -> None:
        self._start = None
        self._sank = False
        self._stopped = 0
        self.starts = []
        self.landed = None
        self.depth = None
        self.depths = []

    def update(self, dropped: bool, estimate: EstimatedState) -> bool:
        """Take this tick's drop detection and estimate; whether the drop is in the air.

        Args:
            dropped: Whether the drop detector tells a drop this tick.
            estimate: The state estimate (its time, base and feet).

        Returns:
            True from a drop until, once a foot has sunk faster than ``SINK_SPEED``, every
            foot has sunk slower for ``LAND_TICKS`` ticks (a landing ends a fall).
        """
        if self._start is None:
            if dropped:
                self._start = estimate.time
                self.starts.append(estimate.time)
                self._offsets = estimate.foot_position - estimate.base_position
                self._height = float(np.mean(estimate.foot_position[:, 2]))
                self._sank = False
                self._stopped = 0
            return self.flying
        sinking = float(np.min(estimate.foot_velocity[:, 2]))
        self._sank = self._sank or sinking < -SINK_SPEED
        landed = self._sank and sinking >= -SINK_SPEED
        self._stopped = self._stopped + 1 if landed else 0
        if self._stopped >= LAND_TICKS:
            self._start = None
            self.landed = estimate.time
            self.depth = self._height - float(np.mean(estimate.foot_position[:, 2]))
            self.depths.append(self.depth)
        return self.flying

    def observe(self, tick: ControlTick) -> None:
        """Take this tick's drop (the watch's, observed first) while the MPC rides."""
        self._now = tick.sensors.time
        dropped = self.watch is not None and self.watch.dropping and not tick.on_backup
        self.update(dropped, tick.estimate)

    def __call__(self, check: HandoverCheck) -> str | None:
        """The drop's handover: a flight longer than any step's."""
        return "every foot's load gone at once (a drop)" if self.too_long(self._now) else None

    def feet(self, feet: FootTargets, estimate: EstimatedState) -> tuple[FootTargets, Array]:
        """The feet's targets through the flight: none in contact, each swinging after its
        platform (``swing``), and the swing's feedforward acceleration [m/s^2]."""
        position, velocity, acceleration = self.swing(estimate)
        contact = np.zeros_like(feet.contact)
        return FootTargets(contact, position, velocity, feet.posture), acceleration

    def too_long(self, now: float) -> bool:
        """Whether this flight has outlasted any step's (``LONGEST_S``)."""
        return self._start is not None and now - self._start > LONGEST_S

    def swing(self, estimate: EstimatedState) -> tuple[Array, Array, Array]:
        """The feet's swing targets this tick: position [m], velocity [m/s] and feedforward
        acceleration [m/s^2], each of shape (feet, 3), world frame."""
        assert self._start is not None
        reach = min(self.extend_speed * (estimate.time - self._start), self.max_extension)
        reaching = self.extend_speed if reach < self.max_extension else 0.0
        up = np.array([0.0, 0.0, 1.0])
        position = estimate.base_position + self._offsets - reach * up
        shape = position.shape
        velocity = np.broadcast_to(estimate.base_velocity - reaching * up, shape).copy()
        acceleration = np.broadcast_to(-GRAVITY * up, shape).copy()
        return position, velocity, acceleration
