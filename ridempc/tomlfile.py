"""Reading checked TOML files: one place that turns any problem into a one-line ConfigError."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from ridempc.checks import text_file
from ridempc.errors import ConfigError

__all__ = ["load_checked", "read_toml", "validate"]

Model = TypeVar("Model", bound=BaseModel)


def read_toml(path: Path, what: str) -> dict[str, Any]:
    """The TOML table in ``path``; ``what`` names the file's role in the error message.

    Raises:
        ConfigError: Missing, a folder, unreadable, not UTF-8 or not TOML.
    """
    text = text_file(path, what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from exc


def validate(path: Path, raw: dict[str, Any], model: type[Model]) -> Model:
    """``raw`` checked against ``model``; the first bad field is named on failure."""
    try:
        return model.model_validate(raw)
    except ValidationError as exc:
        raise ConfigError.from_validation(path, exc, model) from exc


def load_checked(path: Path, model: type[Model], what: str) -> Model:
    """Read and check a TOML file in one step."""
    return validate(path, read_toml(path, what), model)
