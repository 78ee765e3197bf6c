"""The recent past of the filter, to meet measurements that arrive late.

The VIO delivers a sample ``vio_latency`` seconds after it was captured. Comparing it with
the current state would attribute to now a motion that happened over the latency (at
1 m/s and 30 ms, a 3 cm error). :class:`StateHistory` keeps the filter's mean and what is
needed to move a base measurement to the IMU point, at every tick of the last
``history`` seconds, and gives them at the capture stamp by linear interpolation
between the two ticks around it. The filter then compares the sample with the state of
its stamp, :math:`y = z(t_c) - H x(t_c)`, and applies the correction :math:`K y` to the
current state (the error at :math:`t_c` persists to now: positions and velocities change
by the integrated IMU and legs, which the correction does not touch). The same correction
is added to the stored states after :math:`t_c`, so a later sample captured before this
one arrived is not corrected twice.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["HistoryEntry", "StateHistory"]

Array = NDArray[np.float64]


@dataclass
class HistoryEntry:
    """The filter at one tick.

    Attributes:
        time: [s].
        x: State mean after the tick's update.
        imu_offset: :math:`d_S` [m], IMU point minus base origin, world axes.
        imu_offset_rate: :math:`w_S` [m/s], its rate.
    """

    time: float
    x: Array
    imu_offset: Array
    imu_offset_rate: Array


class StateHistory:
    """A time-ordered ring of :class:`HistoryEntry` covering ``span`` seconds."""

    def __init__(self, span: float) -> None:
        self.span = span
        self._entries: deque[HistoryEntry] = deque()

    def __len__(self) -> int:
        return len(self._entries)

    def clear(self) -> None:
        self._entries.clear()

    def append(self, entry: HistoryEntry) -> None:
        self._entries.append(entry)
        while self._entries and self._entries[0].time < entry.time - self.span:
            self._entries.popleft()

    def at(self, stamp: float) -> HistoryEntry | None:
        """The state at ``stamp`` [s], interpolated; None if outside the stored span."""
        entries = self._entries
        if not entries or stamp < entries[0].time or stamp > entries[-1].time:
            return None
        after = len(entries) - 1
        while after > 0 and entries[after - 1].time >= stamp:
            after -= 1
        b = entries[after]
        if after == 0 or b.time == stamp:
            return b
        a = entries[after - 1]
        s = (stamp - a.time) / (b.time - a.time)
        return HistoryEntry(
            time=stamp,
            x=(1 - s) * a.x + s * b.x,
            imu_offset=(1 - s) * a.imu_offset + s * b.imu_offset,
            imu_offset_rate=(1 - s) * a.imu_offset_rate + s * b.imu_offset_rate,
        )

    def shift_after(self, stamp: float, correction: Array) -> None:
        """Add ``correction`` to the stored means later than ``stamp`` [s] (the newest is the
        filter's current state, which the correction has just moved)."""
        for entry in reversed(self._entries):
            if entry.time <= stamp:
                break
            entry.x = entry.x + correction
