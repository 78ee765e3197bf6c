"""Checking a scenario's ``push_off.hold`` against the pair's motion library.

Holding the speed after a push-off means pushing again from the rolling board, which only a
pair whose motion library has ``repush`` entries can (the skateboard's): elsewhere the flag
would be silently ignored, so it is refused as bad input before anything is simulated.
"""

from __future__ import annotations

from ridempc.errors import ConfigError
from ridempc.library.format import MANIFEST
from ridempc.library.store import library_folder, read_manifest
from ridempc.scenarios.scenario import Scenario

__all__ = ["REPUSH_KIND", "check_hold"]

REPUSH_KIND: str = "repush"  # the library kind of a push from a rolling board


def check_hold(scenario: Scenario, robot: str | None, board: str) -> None:
    """Refuse ``push_off.hold`` for a pair whose motion library has no ``repush`` entries
    (no robot, a dead weight, holds nothing and is not refused).

    Raises:
        ConfigError: Naming the scenario, the field, the value and what is allowed.
    """
    push_off = scenario.push_off
    if push_off is None or not push_off.hold or robot is None:
        return
    folder = library_folder(robot, board)
    kinds = (
        {e.kind for e in read_manifest(folder).entries} if (folder / MANIFEST).is_file() else set()
    )
    if REPUSH_KIND not in kinds:
        raise ConfigError(
            f"scenario '{scenario.name}': field 'push_off.hold' is true; allowed: true only "
            f"for a pair whose motion library has '{REPUSH_KIND}' entries (robot '{robot}' "
            f"on board '{board}' has none in {folder})"
        )
