"""Multi-rate scheduling in whole physics steps, so every rate is exact in simulation time.

The physics runs at ``physics_hz``; a task at ``rate_hz`` runs every
``physics_hz / rate_hz`` steps, which must be a whole number: at the default 1500 Hz,
500 Hz is every 3 steps and 30 Hz every 50 steps, with no drift however long the run.
Time is ``tick / physics_hz``, computed from the integer tick, never accumulated.
"""

from __future__ import annotations

from dataclasses import dataclass

from ridempc.errors import ConfigError

__all__ = ["DEFAULT_PHYSICS_HZ", "Rate"]

DEFAULT_PHYSICS_HZ: int = 1500  # [Hz] least common multiple of 500 Hz (WBC) and 30 Hz (MPC)


@dataclass(frozen=True)
class Rate:
    """A task rate expressed as a whole number of physics steps.

    Attributes:
        hz: Task rate [Hz].
        period: Physics steps between two runs of the task.
    """

    hz: float
    period: int

    @classmethod
    def of(cls, hz: float, physics_hz: int, what: str = "task") -> Rate:
        """Rate for a task at ``hz`` on a physics clock at ``physics_hz``.

        Raises:
            ConfigError: ``hz`` is not positive, exceeds the physics rate or does not
                divide it.
        """
        if hz <= 0 or hz > physics_hz:
            raise ConfigError(f"{what} rate {hz} Hz must be in (0, {physics_hz}] Hz")
        period = round(physics_hz / hz)
        if abs(period * hz - physics_hz) > 1e-9 * physics_hz:
            raise ConfigError(
                f"{what} rate {hz} Hz does not divide the physics rate {physics_hz} Hz"
            )
        return cls(hz=float(hz), period=period)

    def due(self, tick: int) -> bool:
        """Whether the task runs at this physics step."""
        return tick % self.period == 0
