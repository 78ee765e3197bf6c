"""The skateboard's firmware: there is none.

A skateboard has no electronics: no motors, no controller, nothing that reads a sensor.
Its steering is mechanical (the raked trucks, eq. 11) and its roll restoring torque is the
bushings' (eq. 6). :class:`PassiveFirmware` stands in for it so that every board has a
firmware: it runs at any rate the board file states (a divisor of the physics rate) and
does nothing.
"""

from __future__ import annotations

from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.boards.parameters import BoardParameters

__all__ = ["PassiveFirmware", "make_firmware"]


class PassiveFirmware(Firmware):
    """A passive no-op: the skateboard has no electronics, so :meth:`update` does nothing."""

    def update(self) -> None:
        """Nothing to do: no sensor is read and no actuator exists."""


def make_firmware(params: BoardParameters, io: BoardIO) -> Firmware:
    """The skateboard's (no-op) firmware."""
    return PassiveFirmware(params, io)
