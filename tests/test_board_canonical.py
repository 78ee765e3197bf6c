"""Every board's reduced model says what each of its states is, by the canonical quantities
every board shares (:mod:`ridempc.boards.canonical`), and says it right: the quantity named
``heading`` or ``speed`` is the one the model's own dynamics read as such."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.boards.canonical import (
    QUANTITIES,
    BoardState,
    board_state_columns,
    canonical_board_states,
)
from ridempc.trajopt.platforms import wheeled_board
from ridempc.trajopt.skateboard import BOARD_STATE, skateboard_model


@pytest.mark.parametrize("name", ["hovershoes", "segway"])
def test_a_wheeled_boards_states_are_named_by_quantity(name: str) -> None:
    model = wheeled_board(load_board(name))  # type: ignore[arg-type]
    states = model.board_states()
    assert set(states) == set(model.state_names)
    assert {s.quantity for s in states.values()} <= set(QUANTITIES)
    columns = board_state_columns(model.state_names, states)
    xb = np.arange(len(model.state_names), dtype=float)
    for k in range(model.n_platforms):
        assert float(model.heading(xb, k)) == xb[columns[BoardState(k, "heading")]]
        assert float(model.speed(xb, k)) == xb[columns[BoardState(k, "speed")]]
        assert model.heading_index(k) == columns[BoardState(k, "heading")]
        for quantity in ("x", "y", "pitch", "pitch_rate", "yaw_rate"):
            assert BoardState(k, quantity) in columns
        prefix = model.platform_prefixes()[k]
        assert all(n.startswith(prefix) for n, s in states.items() if s.platform == k)


def test_the_decks_states_are_named_by_quantity() -> None:
    model = skateboard_model(load_board("skateboard"))  # type: ignore[arg-type]
    states = model.board_states()
    assert set(states) == set(BOARD_STATE)
    columns = board_state_columns(BOARD_STATE, states)
    assert {s.quantity for s in columns} == {"x", "y", "heading", "speed", "roll", "roll_rate"}
    assert all(n.startswith(model.platform_prefixes()[0]) for n in BOARD_STATE)


def test_an_unknown_quantity_is_refused() -> None:
    with pytest.raises(ValueError, match="quantity 'tilt': allowed: x, y"):
        canonical_board_states(("a_",), {"t": "tilt"})
