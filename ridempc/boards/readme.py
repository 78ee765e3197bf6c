"""Board READMEs that agree with their ``board.toml``: the identified-parameter table generated.

Each board README carries its reduced model's identified parameters between two markers; the
table is made here from the board's checked ``[reduced]`` table, its units and meanings from the
``Attributes:`` section of the kind's reduced-parameter model, so a re-identification that
changes ``board.toml`` changes the README with it. ``tests/test_board_readmes.py`` fails when a
README's table differs from what this module makes; ``python -m ridempc.boards.readme`` writes
the tables anew (``--check`` only reports).
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from pydantic import BaseModel

from ridempc.boards.registry import NO_BOARD, board_names, load_board
from ridempc.errors import ConfigError
from ridempc.paths import boards_dir

__all__ = [
    "BEGIN",
    "END",
    "attribute_docs",
    "readme_path",
    "reduced_table",
    "render_readme",
]

BEGIN = (
    "<!-- identified parameters: generated from board.toml [reduced] by "
    "`python -m ridempc.boards.readme`; tests/test_board_readmes.py checks it -->"
)
END = "<!-- end of the generated table -->"

_ATTRIBUTE = re.compile(r"^(\s+)(\w+): (.*)$")
_UNIT = re.compile(r"\s*\[([^\[\]]*)\]\.?\s*$")
_MATH = re.compile(r":math:`([^`]*)`")


def attribute_docs(model: type[BaseModel]) -> dict[str, tuple[str, str]]:
    """Field name -> (meaning, unit) from a Google-style ``Attributes:`` docstring section.

    A field's text may run over several indented lines; its unit is the last bracketed group
    (``[N m / rad]``), and ``:math:`x``` becomes ``x``.
    """
    lines = (model.__doc__ or "").splitlines()
    try:
        start = next(i for i, line in enumerate(lines) if line.strip() == "Attributes:")
    except StopIteration:
        return {}
    entries: dict[str, list[str]] = {}
    indent: int | None = None
    current = None
    for line in lines[start + 1 :]:
        if not line.strip():
            break
        match = _ATTRIBUTE.match(line)
        if match and (indent is None or len(match.group(1)) == indent):
            indent = len(match.group(1))
            current = match.group(2)
            entries[current] = [match.group(3)]
        elif current is not None:
            entries[current].append(line.strip())
    docs: dict[str, tuple[str, str]] = {}
    for name, parts in entries.items():
        text = _MATH.sub(r"\1", " ".join(parts)).replace("\\\\", "\\")
        unit_match = _UNIT.search(text)
        unit = unit_match.group(1) if unit_match else ""
        meaning = text[: unit_match.start()] if unit_match else text.rstrip(".")
        docs[name] = (meaning.strip().rstrip(":,"), unit)
    return docs


def reduced_table(board_name: str) -> str:
    """The Markdown table of a board's ``[reduced]`` parameters, as ``board.toml`` holds them.

    Raises:
        ConfigError: The board has no ``[reduced]`` table.
    """
    board = load_board(board_name)
    reduced = None if board is None else getattr(board.params, "reduced", None)
    if not isinstance(reduced, BaseModel):
        raise ConfigError(f"board '{board_name}': board.toml has no [reduced] table")
    docs = attribute_docs(type(reduced))
    rows = ["| parameter | value | unit | meaning |", "| --- | --- | --- | --- |"]
    for name, value in reduced.model_dump().items():
        meaning, unit = docs.get(name, ("", ""))
        rows.append(f"| `{name}` | {value!r} | {unit} | {meaning} |")
    return "\n".join(rows)


def readme_path(board_name: str) -> Path:
    return boards_dir() / board_name / "README.md"


def render_readme(board_name: str, text: str) -> str:
    """``text`` (a README) with the table between the markers made anew.

    Raises:
        ConfigError: The README does not hold the two markers, in order, once each.
    """
    begin, end = text.find(BEGIN), text.find(END)
    if begin < 0 or end < begin or text.count(BEGIN) != 1 or text.count(END) != 1:
        raise ConfigError(
            f"{readme_path(board_name)}: needs the generated table's two markers, once each "
            f"and in order ({BEGIN} ... {END})"
        )
    head = text[: begin + len(BEGIN)]
    return f"{head}\n{reduced_table(board_name)}\n{text[end:]}"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m ridempc.boards.readme",
        description="Write each board README's identified-parameter table from its board.toml.",
    )
    parser.add_argument("--check", action="store_true", help="only report stale READMEs")
    args = parser.parse_args(argv)
    stale = []
    for name in board_names():
        if name == NO_BOARD:
            continue
        path = readme_path(name)
        text = path.read_text(encoding="utf-8")
        new = render_readme(name, text)
        if new != text:
            stale.append(str(path))
            if not args.check:
                path.write_text(new, encoding="utf-8")
    verb = "stale" if args.check else "written"
    print(f"{verb}: {', '.join(stale)}" if stale else "every board README agrees with board.toml")
    return 1 if stale and args.check else 0


if __name__ == "__main__":
    sys.exit(main())
