"""The package's own exceptions: each names what failed and, where it helps, the valid values."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pydantic import ValidationError

__all__ = [
    "ConfigError",
    "RidempcError",
    "SimulationDiverged",
    "UnknownNameError",
]


_SCALARS = (str, int, float, bool, type(None))


def _shown(value: object) -> str:
    """A bad input as the user wrote it (TOML spelling for booleans), cut to one short line."""
    if isinstance(value, bool):
        return "true" if value else "false"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


class RidempcError(Exception):
    """Base class of every error ridempc raises on purpose."""


class UnknownNameError(RidempcError, KeyError):
    """A robot, board, controller or scenario name that does not exist."""

    def __init__(self, kind: str, name: str, valid: Iterable[str]) -> None:
        self.kind = kind
        self.name = name
        self.valid = tuple(sorted(valid))
        super().__init__(f"unknown {kind} '{name}' (valid: {', '.join(self.valid) or 'none'})")

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


class ConfigError(RidempcError, ValueError):
    """A parameter, scenario or library file that is missing, malformed or non-physical."""

    @classmethod
    def from_validation(cls, path: Path | str, exc: ValidationError) -> ConfigError:
        """One line naming the file, the first bad field, its value and what is allowed."""
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"])
        field = f" field '{where}':" if where else ""
        message = first["msg"].removeprefix("Value error, ")  # our own validators' words
        more = f" (and {exc.error_count() - 1} more)" if exc.error_count() > 1 else ""
        got = ""
        if first["type"] != "missing" and isinstance(first.get("input"), _SCALARS):
            got = f", got {_shown(first['input'])}"
        return cls(f"{path}:{field} {message}{got}{more}")


class SimulationDiverged(RidempcError, RuntimeError):
    """The physics produced NaN or exploded; the run is recorded as failed."""

    def __init__(self, time: float, what: str) -> None:
        self.time = time
        self.what = what
        super().__init__(f"simulation diverged at t = {time:.4f} s: {what}")
