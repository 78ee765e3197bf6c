"""The scenario library: TOML files shipped with the package, runnable by name.

``library/<name>.toml`` is a scenario for any pair it applies to; ``library/<board>/<name>.toml``
is that scenario's variant for one board (its speeds, its kick on the board). A name
resolves to the board's variant where there is one.
"""

from __future__ import annotations

from pathlib import Path

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.scenarios.scenario import Scenario, load_scenario_file

__all__ = ["LIBRARY_DIR", "library_files", "resolve_scenario", "scenario_applies", "scenario_names"]

LIBRARY_DIR = Path(__file__).resolve().parent / "library"


def scenario_names() -> tuple[str, ...]:
    return tuple(sorted({p.stem for p in LIBRARY_DIR.glob("**/*.toml")}))


def _library_file(name: str, board: str | None) -> Path | None:
    if board is not None and (LIBRARY_DIR / board / f"{name}.toml").exists():
        return LIBRARY_DIR / board / f"{name}.toml"
    generic = LIBRARY_DIR / f"{name}.toml"
    return generic if generic.exists() else None


def resolve_scenario(name_or_path: str, board: str | None = None) -> Scenario:
    """A scenario by library name (``board``'s variant if any), or from a ``.toml`` path.

    Raises:
        UnknownNameError: Not a library name and not a ``.toml`` path.
        ConfigError: A path that is missing, not a readable UTF-8 file or malformed, or a
            name with no variant for ``board``.
    """
    if name_or_path.lower().endswith(".toml") or "/" in name_or_path:  # a path, not a name
        return load_scenario_file(Path(name_or_path))
    if name_or_path not in scenario_names():
        raise UnknownNameError("scenario", name_or_path, scenario_names())
    path = _library_file(name_or_path, board)
    if path is None:
        boards = sorted(p.parent.name for p in LIBRARY_DIR.glob(f"*/{name_or_path}.toml"))
        raise ConfigError(
            f"scenario '{name_or_path}' does not apply to board '{board}' "
            f"(it exists for: {', '.join(boards)})"
        )
    return load_scenario_file(path)


def library_files() -> tuple[Path, ...]:
    """Every scenario file of the library (generic ones and board variants)."""
    return tuple(sorted(LIBRARY_DIR.glob("**/*.toml")))


def scenario_applies(name: str, robot: str, board: str) -> bool:
    """Whether the library scenario ``name`` has a version for this robot-board pair."""
    path = _library_file(name, board)
    return path is not None and load_scenario_file(path).applies_to(robot, board)
