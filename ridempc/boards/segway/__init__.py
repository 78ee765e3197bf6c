"""The Segway (miniPro class): one platform on two wheels, a knee bar, pitch-balancing firmware.

Exposes :data:`KIND` for :mod:`ridempc.boards.kinds`.
"""

from ridempc.boards.kinds import BoardKind
from ridempc.boards.segway.firmware import SegwayFirmware
from ridempc.boards.segway.identify import identify
from ridempc.boards.segway.model import build_segway
from ridempc.boards.segway.parameters import (
    SegwayGains,
    SegwayParameters,
    SegwayReducedParameters,
)

KIND = BoardKind(
    parameters=SegwayParameters,
    build=build_segway,
    firmware=SegwayFirmware,
    identify=identify,
    features=frozenset({"knee_bar"}),
)

__all__ = [
    "KIND",
    "SegwayFirmware",
    "SegwayGains",
    "SegwayParameters",
    "SegwayReducedParameters",
    "build_segway",
    "identify",
]
