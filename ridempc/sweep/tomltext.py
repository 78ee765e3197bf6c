"""TOML text of a table of plain values, exact for every number: what a scenario dumps.

The subset a checked model dumps: strings, booleans, integers, finite floats, lists of
those (and of lists), tables, and lists of tables (``[[name]]``). A float is written as
Python's ``repr``, the shortest text that reads back to the same double, so a file written
here and read with :mod:`tomllib` gives the same numbers bit for bit.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["toml_text"]

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n"}
_ESCAPES |= {"\f": "\\f", "\r": "\\r"}


def toml_text(table: Mapping[str, Any]) -> str:
    """``table`` as TOML: its plain keys first, then its tables and lists of tables.

    Raises:
        ValueError: A value TOML cannot hold (None, NaN, infinity, another type).
    """
    lines: list[str] = []
    _table(lines, table, ())
    return "\n".join(lines).lstrip("\n") + "\n"


def _is_table(value: Any) -> bool:
    return isinstance(value, Mapping)


def _is_table_list(value: Any) -> bool:
    return _is_sequence(value) and bool(value) and all(_is_table(v) for v in value)


def _is_sequence(value: Any) -> bool:
    return isinstance(value, Sequence) and not isinstance(value, str)


def _table(lines: list[str], table: Mapping[str, Any], path: tuple[str, ...]) -> None:
    for key, value in table.items():
        if not (_is_table(value) or _is_table_list(value)):
            lines.append(f"{_key(key)} = {_value(value)}")
    for key, value in table.items():
        header = ".".join(_key(k) for k in (*path, key))
        if _is_table(value):
            lines += ["", f"[{header}]"]
            _table(lines, value, (*path, key))
        elif _is_table_list(value):
            for item in value:
                lines += ["", f"[[{header}]]"]
                _table(lines, item, (*path, key))


def _key(key: str) -> str:
    return key if _BARE_KEY.match(key) else _string(key)


def _string(text: str) -> str:
    out = []
    for char in text:
        if char in _ESCAPES:
            out.append(_ESCAPES[char])
        elif ord(char) < 0x20 or ord(char) == 0x7F:  # other control characters
            out.append(f"\\u{ord(char):04x}")
        else:
            out.append(char)
    return '"' + "".join(out) + '"'


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"{value}: a scenario's numbers are finite")
        return repr(value)
    if isinstance(value, str):
        return _string(value)
    if _is_sequence(value):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise ValueError(f"{value!r}: TOML has no such value")
