"""The scenario library: TOML files shipped with the package, runnable by name."""

from __future__ import annotations

from pathlib import Path

from ridempc.errors import UnknownNameError
from ridempc.scenarios.scenario import Scenario, load_scenario_file

__all__ = ["LIBRARY_DIR", "resolve_scenario", "scenario_names"]

LIBRARY_DIR = Path(__file__).resolve().parent / "library"


def scenario_names() -> tuple[str, ...]:
    return tuple(sorted(p.stem for p in LIBRARY_DIR.glob("*.toml")))


def resolve_scenario(name_or_path: str) -> Scenario:
    """A scenario by library name, or from a file path (anything ending in ``.toml``).

    Raises:
        UnknownNameError: Not a library name and not a ``.toml`` path.
        ConfigError: The file is malformed.
    """
    if name_or_path.endswith(".toml") or "/" in name_or_path:
        return load_scenario_file(Path(name_or_path))
    if name_or_path not in scenario_names():
        raise UnknownNameError("scenario", name_or_path, scenario_names())
    return load_scenario_file(LIBRARY_DIR / f"{name_or_path}.toml")
