"""Board firmware: the logic a real board runs, reading only the board's own sensors.

The firmware gets a :class:`BoardIO`, which exposes the board's own MuJoCo sensors (its
IMU, wheel encoders, knee-bar angle...) and its own actuators (wheel motors), by their
unprefixed names, and nothing else: no ``qpos``, no rider state, no contact forces.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.parameters import BoardParameters
from ridempc.errors import ConfigError

__all__ = ["BoardIO", "Firmware"]


class BoardIO:
    """The board's sensors and actuators in a compiled scene, named without the board prefix.

    Args:
        model: The compiled scene.
        prefix: Name prefix of the board's elements in the scene (``board/``).
    """

    def __init__(self, model: mujoco.MjModel, prefix: str) -> None:
        self._sensors: dict[str, slice] = {}
        for i in range(model.nsensor):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SENSOR, i) or ""
            if name.startswith(prefix):
                adr, dim = int(model.sensor_adr[i]), int(model.sensor_dim[i])
                self._sensors[name[len(prefix) :]] = slice(adr, adr + dim)
        self._actuators: dict[str, int] = {}
        for i in range(model.nu):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, i) or ""
            if name.startswith(prefix):
                self._actuators[name[len(prefix) :]] = i
        self._ctrl_range = np.array(model.actuator_ctrlrange)
        self._data: mujoco.MjData | None = None

    @property
    def actuator_ids(self) -> tuple[int, ...]:
        return tuple(self._actuators.values())

    def bind(self, data: mujoco.MjData) -> None:
        self._data = data

    def time(self) -> float:
        assert self._data is not None
        return float(self._data.time)

    def sensor(self, name: str) -> NDArray[np.float64]:
        """A copy of one of the board's sensor readings."""
        if name not in self._sensors:
            raise ConfigError(f"board has no sensor '{name}' (has: {', '.join(self._sensors)})")
        assert self._data is not None, "BoardIO used before bind()"
        return np.array(self._data.sensordata[self._sensors[name]])

    def actuate(self, name: str, value: float) -> float:
        """Set one of the board's actuators, clipped to its control range; returns the value set."""
        if name not in self._actuators:
            raise ConfigError(f"board has no actuator '{name}' (has: {', '.join(self._actuators)})")
        assert self._data is not None, "BoardIO used before bind()"
        i = self._actuators[name]
        low, high = self._ctrl_range[i]
        value = float(value)  # clipped in Python floats (np.clip's wrapper costs 4 us)
        if high > low:
            value = float(min(max(value, low), high))
        self._data.ctrl[i] = value
        return value


class Firmware(ABC):
    """A board's embedded controller.

    Args:
        params: The board's parameters (gains, limits).
        io: The board's own sensors and actuators.

    Attributes:
        rate_hz: How often :meth:`update` runs [Hz] (``params.firmware_hz``).
    """

    def __init__(self, params: BoardParameters, io: BoardIO) -> None:
        self.params = params
        self.io = io
        self.rate_hz = params.firmware_hz

    def reconfigure(self, params: BoardParameters) -> None:
        """Run on ``params`` from the next tick (a scenario's change of gains or wheel)."""
        self.params = params

    @abstractmethod
    def update(self) -> None:
        """One firmware tick: read the board's sensors, set the board's actuators."""

    def diagnostics(self) -> dict[str, float]:
        """Scalars to log at this tick (tilt estimate, wheel command, ...)."""
        return {}
