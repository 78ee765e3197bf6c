"""A sweep's folder: where each file goes, and the manifest that keeps two sweeps apart.

::

    DIR/sweep.toml                    the arguments that define the rides (the manifest)
    DIR/variants/<id>.toml            each variant as a scenario file (``sim --scenario``)
    DIR/rides/<id>/<controller>.json  each ride's summary, written when the ride has ended
    DIR/sweep.json                    the statistics, written once every ride is recorded
    DIR/report.md, DIR/report.html    the report (the HTML with its plots embedded)

A sweep started again in its folder with the same arguments resumes: it rides only what
has no summary yet. With other arguments (robot, board, scenario or its file's content,
distribution or its content, controllers, seed, duration) it is refused, so a folder never
mixes two sweeps; ``--samples`` may differ, since the first N variants of a seed are the
same whatever N is.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from ridempc.errors import ConfigError
from ridempc.io import atomic_write_text
from ridempc.tomlfile import load_checked
from ridempc.units import CheckedModel

__all__ = ["REPORT_FILES", "SweepLayout", "SweepManifest", "digest"]

# Written once every ride is recorded; removed when a sweep (re)starts, so that none of them
# ever describes fewer rides than the folder holds, or an unfinished sweep.
REPORT_FILES: tuple[str, ...] = ("sweep.json", "report.md", "report.html")


def digest(model: Any) -> str:
    """SHA-256 of a checked model's content (a scenario, a distribution): the manifest
    tells a changed file from the same one."""
    if hasattr(model, "model_dump"):
        text = json.dumps(model.model_dump(mode="json"), sort_keys=True)
    else:
        text = repr(model)
    return hashlib.sha256(text.encode()).hexdigest()


class SweepManifest(CheckedModel):
    """What defines a sweep's rides (``sweep.toml``)."""

    robot: str
    board: str
    scenario: str
    scenario_sha256: str
    distribution: str
    distribution_sha256: str
    controllers: tuple[str, ...]
    seed: int
    duration: float | None = None

    def toml(self) -> str:
        lines = ["# ridempc sweep: the arguments that define the rides in this folder"]
        for key, value in self.model_dump().items():
            if value is not None:
                lines.append(f"{key} = {json.dumps(value)}")  # JSON's strings, lists: TOML's
        return "\n".join(lines) + "\n"


class SweepLayout:
    """The paths of a sweep's folder (module docstring)."""

    def __init__(self, folder: Path) -> None:
        self.folder = Path(folder)
        self.manifest = self.folder / "sweep.toml"
        self.variants = self.folder / "variants"
        self.rides = self.folder / "rides"
        self.sweep_json = self.folder / "sweep.json"
        self.report_md = self.folder / "report.md"
        self.report_html = self.folder / "report.html"

    def variant_file(self, variant: str) -> Path:
        return self.variants / f"{variant}.toml"

    def ride_file(self, variant: str, controller: str) -> Path:
        return self.rides / variant / f"{controller}.json"

    def check(self, manifest: SweepManifest) -> None:
        """Refuse a folder that holds another sweep, or rides without a manifest.

        Raises:
            ConfigError: One line naming the first argument that differs.
        """
        for name in (*REPORT_FILES, "sweep.toml", "variants", "rides"):
            path = self.folder / name
            wanted_dir = name in ("variants", "rides")
            if path.exists() and path.is_dir() != wanted_dir:
                kind = "a folder" if path.is_dir() else "a file"
                raise ConfigError(
                    f"{path}: {kind} where a sweep writes its '{name}'; allowed: an --out "
                    "folder without it"
                )
        if not self.manifest.exists():
            if self.rides.exists() or self.variants.exists():
                raise ConfigError(
                    f"{self.folder}: holds rides or variants but no sweep.toml saying what they "
                    "are; allowed: a new --out folder"
                )
            return
        recorded = load_checked(self.manifest, SweepManifest, "sweep manifest")
        for key, value in manifest.model_dump().items():
            before = getattr(recorded, key)
            if before != value:
                raise ConfigError(
                    f"{self.manifest}: this folder holds a sweep with {key} = {_shown(before)}, "
                    f"not {_shown(value)}; allowed: the same arguments (to resume it) or "
                    "another --out folder"
                )

    def start(self, manifest: SweepManifest) -> None:
        """Write the manifest and remove the statistics and report of an earlier run."""
        self.folder.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.manifest, manifest.toml())
        for name in REPORT_FILES:
            (self.folder / name).unlink(missing_ok=True)

    def write_variant(self, variant: str, text: str) -> None:
        """Write a variant's scenario file; one already there must be the same.

        Raises:
            ConfigError: The file holds another scenario (drawn by another ridempc version,
                or edited): the recorded rides would not be its rides.
        """
        path = self.variant_file(variant)
        if path.exists():
            if path.read_text() != text:
                raise ConfigError(
                    f"{path}: differs from the variant drawn now (edited, or drawn by another "
                    "ridempc version); allowed: a new --out folder"
                )
            return
        atomic_write_text(path, text)


def _shown(value: Any) -> str:
    if isinstance(value, str) and len(value) == 64:  # a digest
        return value[:12] + "..."
    return json.dumps(value)
