"""Skateboard: a deck on two raked trucks with bushings, four passive wheels, no electronics.

The skateboard paper's board (CyberDog2 skateboarding): steering by leaning comes from the
trucks' geometry (eq. 11-14), the deck's roll from the bushings' spring-damper (eq. 6).
"""

from ridempc.boards.kinds import BoardKind
from ridempc.boards.skateboard.firmware import PassiveFirmware, make_firmware
from ridempc.boards.skateboard.identify import identify
from ridempc.boards.skateboard.model import build_skateboard
from ridempc.boards.skateboard.parameters import SkateboardParameters, SkateboardReducedParameters

__all__ = [
    "KIND",
    "PassiveFirmware",
    "SkateboardParameters",
    "SkateboardReducedParameters",
    "build_skateboard",
    "identify",
]

KIND = BoardKind(
    parameters=SkateboardParameters,
    build=build_skateboard,  # type: ignore[arg-type]
    firmware=make_firmware,
    identify=identify,
    features=frozenset({"deck_roll"}),
)
