"""Atomic file writes: a file is either complete or absent, never half-written."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import IO, Any

import numpy as np

from ridempc.errors import WriteFailed

__all__ = [
    "atomic_savefig",
    "atomic_write",
    "atomic_write_json",
    "atomic_write_npz",
    "atomic_write_text",
]

_UMASK = os.umask(0)
os.umask(_UMASK)


def atomic_write(path: Path, write: Callable[[IO[bytes]], None]) -> None:
    """Write through a temporary file in the same folder, then rename it into place.

    Raises:
        WriteFailed: The file could not be written (the temporary file is removed).
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as exc:
        raise WriteFailed(path, exc) from exc
    try:
        with os.fdopen(fd, "wb") as stream:
            write(stream)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; give the file the usual mode
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise WriteFailed(path, exc) from exc
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    """Write UTF-8 text atomically."""

    def write(stream: IO[bytes]) -> None:
        stream.write(text.encode())

    atomic_write(path, write)


def atomic_write_json(path: Path, payload: Mapping[str, Any]) -> None:
    atomic_write_text(path, json.dumps(payload, indent=2, sort_keys=False, allow_nan=False) + "\n")


def atomic_write_npz(path: Path, arrays: Mapping[str, np.ndarray]) -> None:
    def write(stream: IO[bytes]) -> None:
        np.savez_compressed(stream, **arrays)  # type: ignore[arg-type]

    atomic_write(path, write)


def atomic_savefig(figure: Any, path: Path, dpi: int) -> None:
    """Save a Matplotlib figure as PNG atomically (no half-drawn image after an error)."""

    def write(stream: IO[bytes]) -> None:
        figure.savefig(stream, format="png", dpi=dpi)

    atomic_write(path, write)
