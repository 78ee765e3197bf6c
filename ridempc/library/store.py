"""Reading and writing motion libraries (format in :mod:`ridempc.library.format`).

Writes are atomic (:mod:`ridempc.io`): an entry's file is complete or absent, and the
manifest is rewritten after each stored entry, so an interrupted build leaves a consistent
library of the entries finished so far. Reads verify everything before returning.
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray
from pydantic import ValidationError

from ridempc.checks import readable_file, text_file
from ridempc.errors import ConfigError
from ridempc.io import atomic_write, atomic_write_json
from ridempc.library.format import ARRAYS, FORMAT, MANIFEST, VERSION, EntryRecord, Manifest
from ridempc.paths import motion_library_dir

__all__ = [
    "LibraryEntry",
    "entry_bytes",
    "library_folder",
    "load_entry",
    "load_library",
    "read_manifest",
    "store_entry",
    "write_manifest",
]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class LibraryEntry:
    """A verified stored trajectory: its manifest record and its arrays."""

    record: EntryRecord
    arrays: dict[str, NDArray[Any]]

    @property
    def times(self) -> Array:
        return self.arrays["times"]

    @property
    def states(self) -> Array:
        return self.arrays["states"]

    @property
    def inputs(self) -> Array:
        return self.arrays["inputs"]

    @property
    def midpoints(self) -> Array:
        return self.arrays["midpoints"]

    @property
    def parameters(self) -> Array:
        return self.arrays["parameters"]

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(str(s) for s in self.arrays["state_names"])

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(str(s) for s in self.arrays["input_names"])

    def state(self, name: str) -> Array:
        """One state's time series, by name."""
        if name not in self.state_names:
            raise ConfigError(f"entry '{self.record.name}' has no state '{name}'")
        return self.states[:, self.state_names.index(name)]


def library_folder(robot: str, board: str, root: Path | None = None) -> Path:
    """``<root>/<library>`` (root: the repository's ``motion_library/``), the library the
    pair file names (:mod:`ridempc.pair_description`), ``<robot>-<board>`` for a pair
    without one.

    Raises:
        ConfigError: The pair's file is malformed or does not fit its robot and board.
    """
    from ridempc.pair_description import load_pair_description, pair_description_names

    name = f"{robot}-{board}"
    if name in pair_description_names():
        name = load_pair_description(robot, board).library
    return (root or motion_library_dir()) / name


def entry_bytes(arrays: dict[str, NDArray[Any]]) -> bytes:
    """The ``.npz`` bytes of an entry's arrays (compressed, no pickled objects)."""
    for name, array in arrays.items():
        if array.dtype.kind == "O":
            raise ConfigError(f"array '{name}' holds Python objects; the format forbids them")
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)  # type: ignore[arg-type]
    return buffer.getvalue()


def store_entry(
    folder: Path, record: dict[str, Any], arrays: dict[str, NDArray[Any]]
) -> EntryRecord:
    """Write one entry's file atomically and return its checked manifest record.

    Args:
        folder: The library folder.
        record: The record's fields except ``file`` and ``sha256``.
        arrays: The arrays of :data:`ARRAYS`.

    Raises:
        ConfigError: The record or the arrays do not follow the format (nothing is written).
    """
    data = entry_bytes(arrays)
    fields = {**record, "file": f"{record['name']}.npz", "sha256": hashlib.sha256(data).hexdigest()}
    try:
        checked = EntryRecord.model_validate(fields)
    except ValidationError as exc:
        raise ConfigError.from_validation(f"entry '{record.get('name')}'", exc) from exc
    _check_arrays(folder / checked.file, checked, arrays)

    def write(stream: IO[bytes]) -> None:
        stream.write(data)

    atomic_write(folder / checked.file, write)
    return checked


def write_manifest(folder: Path, robot: str, board: str, entries: list[EntryRecord]) -> Manifest:
    """Write ``manifest.json`` atomically, entries sorted by kind and target."""
    ordered = tuple(sorted(entries, key=lambda e: (e.kind, e.target)))
    manifest = Manifest(format=FORMAT, version=VERSION, robot=robot, board=board, entries=ordered)
    atomic_write_json(folder / MANIFEST, manifest.model_dump(mode="json"))
    return manifest


def read_manifest(folder: Path) -> Manifest:
    """Read and check ``manifest.json``.

    Raises:
        ConfigError: Missing, not JSON, or a field missing or wrong (the field is named).
    """
    path = folder / MANIFEST
    if not path.exists() and not path.is_symlink():
        raise ConfigError(f"{path}: no motion library here (manifest.json not found)")
    text = text_file(path, "motion-library manifest")

    def refuse(constant: str) -> None:  # JSON has no NaN or Infinity; Python's reader takes them
        raise ConfigError(f"{path}: holds {constant}; allowed: finite numbers only")

    try:
        raw = json.loads(text, parse_constant=refuse)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{path}: not valid JSON ({exc})") from exc
    try:
        manifest = Manifest.model_validate(raw)
    except ValidationError as exc:
        raise ConfigError.from_validation(path, exc, Manifest) from exc
    names = [e.name for e in manifest.entries]
    for entry in manifest.entries:
        if entry.file != f"{entry.name}.npz":
            raise ConfigError(
                f"{path}: entry '{entry.name}': file is '{entry.file}', expected '{entry.name}.npz'"
            )
        if names.count(entry.name) > 1:
            raise ConfigError(f"{path}: entry '{entry.name}' appears twice")
    return manifest


def _check_arrays(path: Path, record: EntryRecord, arrays: dict[str, NDArray[Any]]) -> None:
    sizes = record.sizes()
    missing = sorted(set(ARRAYS) - set(arrays))
    if missing:
        raise ConfigError(f"{path}: array '{missing[0]}' is missing")
    extra = sorted(set(arrays) - set(ARRAYS))
    if extra:
        raise ConfigError(f"{path}: unexpected array '{extra[0]}'")
    for name, (kind, shape) in ARRAYS.items():
        array = arrays[name]
        expected = tuple(sizes[s] for s in shape)
        if array.dtype.kind != kind:
            raise ConfigError(
                f"{path}: array '{name}' has dtype {array.dtype}, expected kind '{kind}'"
            )
        if array.shape != expected:
            raise ConfigError(
                f"{path}: array '{name}' has shape {array.shape}, expected {expected}"
            )
        if kind == "f" and not np.all(np.isfinite(array)):
            raise ConfigError(f"{path}: array '{name}' holds NaN or infinite values")
    times = arrays["times"]
    if not np.allclose(np.diff(times), record.dt, rtol=0.0, atol=1e-9):
        raise ConfigError(f"{path}: array 'times' is not a uniform grid of step {record.dt} s")


def load_entry(folder: Path, record: EntryRecord) -> LibraryEntry:
    """Load one entry, verifying its hash and arrays against its record.

    Raises:
        ConfigError: Missing file, hash mismatch, not an ``.npz`` of plain arrays, or an
            array missing or of the wrong dtype, shape or values; the file is named.
    """
    path = readable_file(folder / record.file, "entry file")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ConfigError(f"{path}: entry file is not readable ({exc.strerror})") from exc
    digest = hashlib.sha256(data).hexdigest()
    if digest != record.sha256:
        raise ConfigError(
            f"{path}: content hash {digest[:12]}... does not match the manifest's "
            f"{record.sha256[:12]}... (file changed or corrupt)"
        )
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
    except (ValueError, OSError, zipfile.BadZipFile, EOFError) as exc:
        raise ConfigError(f"{path}: not a readable .npz of plain arrays ({exc})") from exc
    _check_arrays(path, record, arrays)
    return LibraryEntry(record=record, arrays=arrays)


def load_library(folder: Path) -> tuple[Manifest, list[LibraryEntry]]:
    """Read the manifest and load (and verify) every entry."""
    manifest = read_manifest(folder)
    return manifest, [load_entry(folder, record) for record in manifest.entries]
