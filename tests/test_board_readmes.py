"""Each board README agrees with its board.toml (ridempc.boards.readme).

The identified-parameter table is generated from ``[reduced]``; any other figure the README
quotes as ``name`` = value must be the board.toml's.
"""

from __future__ import annotations

import math
import re

import pytest

from ridempc.boards import NO_BOARD, board_names, load_board
from ridempc.boards.readme import BEGIN, attribute_docs, readme_path, reduced_table, render_readme
from ridempc.errors import ConfigError

BOARDS = [name for name in board_names() if name != NO_BOARD]
_QUOTED = re.compile(r"`(\w+)` = (-?\d+(?:\.\d+)?)")


@pytest.mark.parametrize("name", BOARDS)
def test_the_identified_table_is_board_toml(name: str) -> None:
    text = readme_path(name).read_text(encoding="utf-8")
    assert render_readme(name, text) == text, (
        f"{readme_path(name)} is stale: run `python -m ridempc.boards.readme`"
    )


@pytest.mark.parametrize("name", BOARDS)
def test_every_reduced_field_has_a_unit_and_a_meaning(name: str) -> None:
    board = load_board(name)
    assert board is not None
    reduced = board.params.reduced  # type: ignore[attr-defined]
    docs = attribute_docs(type(reduced))
    for field in type(reduced).model_fields:
        meaning, unit = docs[field]
        assert meaning and unit, f"{type(reduced).__name__}.{field}: docstring lacks a unit"
    table = reduced_table(name)
    for field, value in reduced.model_dump().items():
        assert f"| `{field}` | {value!r} |" in table


@pytest.mark.parametrize("name", BOARDS)
def test_quoted_figures_are_board_toml(name: str) -> None:
    board = load_board(name)
    assert board is not None
    fields = board.params.model_dump()
    text = readme_path(name).read_text(encoding="utf-8")
    quoted = [(f, float(v)) for f, v in _QUOTED.findall(text) if f in fields]
    for field, value in quoted:
        assert math.isclose(value, fields[field], rel_tol=1e-9), (
            f"{readme_path(name)} quotes {field} = {value}, board.toml has {fields[field]}"
        )


def test_a_readme_without_markers_is_refused() -> None:
    with pytest.raises(ConfigError, match="markers"):
        render_readme(BOARDS[0], "no table here")
    with pytest.raises(ConfigError, match="markers"):
        render_readme(BOARDS[0], f"{BEGIN}\n{BEGIN}\n")
