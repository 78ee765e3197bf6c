"""A rider holding still who is pushed rides the push out along a library stop
(``ManoeuvreSelector.select``), instead of holding rest at once."""

from __future__ import annotations

import pytest

from ridempc.mpc.manoeuvre import HOLD, RETARGET_BAND, ManoeuvreSelector
from ridempc.scenarios.scenario import Command


@pytest.mark.parametrize("board", ["hovershoes", "segway"])
def test_a_pushed_rider_holding_still_brakes_along_a_stop(board: str) -> None:
    selector = ManoeuvreSelector("cassie", board)
    holding = selector.initial()
    assert holding.kind == HOLD
    rest = Command(velocity=0.0)
    assert selector.select(rest, holding, 3.0, 0.5 * RETARGET_BAND) is holding  # a nudge
    pushed = selector.select(rest, holding, 3.2, 0.6)
    assert pushed.kind == "stop" and pushed.target >= 0.6 - 1e-9
    assert selector.select(rest, pushed, 3.5, 0.4) is pushed  # braking, then at rest


def test_a_board_without_stops_keeps_holding() -> None:
    selector = ManoeuvreSelector("cyberdog2", "skateboard")
    holding = selector.initial()
    assert selector.select(Command(velocity=0.0), holding, 3.2, 0.6) is holding
