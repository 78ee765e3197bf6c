"""The package's own exceptions: each names what failed and, where it helps, the valid values."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from types import UnionType
from typing import TYPE_CHECKING, Annotated, Any, Union, get_args, get_origin

if TYPE_CHECKING:
    from pydantic import ValidationError

__all__ = [
    "ConfigError",
    "RidempcError",
    "SimulationDiverged",
    "UnknownNameError",
    "WriteFailed",
]


_SCALARS = (str, int, float, bool, type(None))


def _shown(value: object) -> str:
    """A bad input as the user wrote it (TOML spelling for booleans), cut to one short line."""
    if isinstance(value, bool):
        return "true" if value else "false"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _bare(annotation: Any) -> Any:
    """An annotation without its ``Annotated`` metadata and its ``| None``."""
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            annotation = get_args(annotation)[0]
        elif origin in (Union, UnionType):
            kept = [a for a in get_args(annotation) if a is not type(None)]
            if len(kept) != 1:
                return annotation
            annotation = kept[0]
        else:
            return annotation


def _keys_at(model: Any, loc: tuple[Any, ...]) -> tuple[str, ...] | None:
    """The keys a model takes in its table at ``loc`` (None where that is not a model)."""
    node = _bare(model)
    for part in loc:
        origin, args = get_origin(node), get_args(node)
        if isinstance(part, str) and hasattr(node, "model_fields"):
            field = node.model_fields.get(part)
            node = None if field is None else _bare(field.annotation)
        elif isinstance(part, str) and origin is dict:
            node = _bare(args[1])
        elif isinstance(part, int) and origin in (tuple, list) and args:
            element = args[0] if len(args) == 1 or args[1] is Ellipsis else args[part]
            node = _bare(element) if part < len(args) or args[-1] is Ellipsis else None
        else:
            return None
    return tuple(node.model_fields) if hasattr(node, "model_fields") else None


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
    def from_validation(
        cls, path: Path | str, exc: ValidationError, model: Any = None
    ) -> ConfigError:
        """One line naming the file, the first bad field, its value and what is allowed.

        Args:
            path: The file (or what was checked).
            exc: Pydantic's error.
            model: The model checked against; with it an unknown key's message lists the
                keys its table takes.
        """
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"])
        field = f" field '{where}':" if where else ""
        message = first["msg"].removeprefix("Value error, ")  # our own validators' words
        more = f" (and {exc.error_count() - 1} more)" if exc.error_count() > 1 else ""
        got = ""
        if first["type"] == "extra_forbidden":
            keys = _keys_at(model, tuple(first["loc"][:-1]))
            allowed = None if keys is None else ", ".join(keys) or "none"
            message = "unknown key" + (f"; allowed: {allowed}" if allowed else "")
        elif first["type"] != "missing" and isinstance(first.get("input"), _SCALARS):
            got = f", got {_shown(first['input'])}"
        return cls(f"{path}:{field} {message}{got}{more}")


class SimulationDiverged(RidempcError, RuntimeError):
    """The physics produced NaN or exploded; the run is recorded as failed."""

    def __init__(self, time: float, what: str) -> None:
        self.time = time
        self.what = what
        super().__init__(f"simulation diverged at t = {time:.4f} s: {what}")


class WriteFailed(RidempcError, OSError):
    """A result that could not be written (disk full, folder removed); nothing half-written
    is left, and the command fails with code 1."""

    def __init__(self, path: Path, reason: OSError) -> None:
        self.path = path
        super().__init__(f"{path}: cannot write it ({reason.strerror or reason}); nothing written")

    def __str__(self) -> str:  # OSError would format its own way
        return str(self.args[0])
