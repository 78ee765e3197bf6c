"""Hovershoes: a pair of independent one-wheel self-balancing platforms, one per foot.

The kind's parameter model, MuJoCo builder, firmware and identification (see
:class:`~ridempc.boards.kinds.BoardKind`); its reduced model (paper eq. (4)-(9)) lives in
:mod:`ridempc.boards.hovershoes.reduced`.
"""

from ridempc.boards.hovershoes.firmware import HovershoesFirmware, make_firmware
from ridempc.boards.hovershoes.identify import identify as _identify
from ridempc.boards.hovershoes.model import build_hovershoes
from ridempc.boards.hovershoes.parameters import HovershoesParameters, HovershoesReducedParameters
from ridempc.boards.kinds import BoardKind

__all__ = [
    "KIND",
    "HovershoesFirmware",
    "HovershoesParameters",
    "HovershoesReducedParameters",
]

KIND = BoardKind(
    parameters=HovershoesParameters,
    build=build_hovershoes,
    firmware=make_firmware,
    identify=_identify,
    features=frozenset({"shoes"}),
)
