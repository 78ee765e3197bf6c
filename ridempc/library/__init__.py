"""Motion libraries: optimised trajectories stored per robot-board pair (no pickle)."""

from ridempc.library.build import BuildReport, EntryOutcome, build_library
from ridempc.library.format import EntryRecord, Manifest
from ridempc.library.store import (
    LibraryEntry,
    library_folder,
    load_entry,
    load_library,
    read_manifest,
)

__all__ = [
    "BuildReport",
    "EntryOutcome",
    "EntryRecord",
    "LibraryEntry",
    "Manifest",
    "build_library",
    "library_folder",
    "load_entry",
    "load_library",
    "read_manifest",
]
