"""Path arguments checked before any work starts: one line naming the path and what is wrong.

Every command checks each path it will read or write here, before it simulates, solves or
benchmarks anything, so a ten-minute command fails in its first second rather than at its
end. The checks never create or change anything: a folder to be written is probed with a
temporary file that is removed at once, in the folder itself or, if it does not exist yet,
in its nearest existing parent (where it will be created).

Each function raises :class:`~ridempc.errors.ConfigError` (exit code 2 at the command line).
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

from ridempc.errors import ConfigError

__all__ = [
    "MAX_TEXT_BYTES",
    "readable_dir",
    "readable_file",
    "text_file",
    "writable_dir",
    "writable_file",
]

# The largest text file read whole (a scenario, a parameter file, a manifest): the biggest
# shipped one is under 100 kB; a larger file is a mistake, not a description.
MAX_TEXT_BYTES: int = 10_000_000


def _mode(path: Path, what: str) -> int | None:
    """The path's ``st_mode``, or None if nothing is there."""
    try:
        return os.stat(path).st_mode
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        raise ConfigError(f"{path}: {what}: a parent of it is a file, not a folder") from None
    except OSError as exc:
        raise ConfigError(f"{path}: {what}: cannot be reached ({exc.strerror})") from None
    except ValueError:  # a NUL byte in the name
        raise ConfigError(f"{path!r}: {what}: not a valid path") from None


def readable_file(path: Path, what: str) -> Path:
    """``path`` if it is an existing, readable file.

    Args:
        path: The file.
        what: Its role, for the message (``"scenario file"``).
    """
    path = Path(path)
    mode = _mode(path, what)
    if mode is None:
        raise ConfigError(f"{path}: {what} not found")
    if stat.S_ISDIR(mode):
        raise ConfigError(f"{path}: {what} is a folder, expected a file")
    if not stat.S_ISREG(mode):  # a device, a pipe, a socket: reading it may never end
        raise ConfigError(f"{path}: {what} is not a regular file")
    try:
        with open(path, "rb"):
            pass
    except OSError as exc:
        raise ConfigError(f"{path}: {what} is not readable ({exc.strerror})") from None
    return path


def text_file(path: Path, what: str) -> str:
    """The UTF-8 text of a readable file.

    Raises:
        ConfigError: As :func:`readable_file`, or the bytes are not UTF-8 (a binary file).
    """
    path = readable_file(path, what)
    size = os.stat(path).st_size
    if size > MAX_TEXT_BYTES:
        raise ConfigError(
            f"{path}: {what} is {size} bytes; allowed: at most {MAX_TEXT_BYTES} bytes of text"
        )
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ConfigError(f"{path}: {what} is not readable ({exc.strerror})") from None
    try:
        return data.decode("utf-8-sig")  # a byte-order mark, as some editors write, is fine
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"{path}: {what} is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})"
        ) from None


def readable_dir(path: Path, what: str) -> Path:
    """``path`` if it is an existing folder whose entries can be listed and read."""
    path = Path(path)
    mode = _mode(path, what)
    if mode is None:
        raise ConfigError(f"{path}: {what} not found")
    if not stat.S_ISDIR(mode):
        raise ConfigError(f"{path}: {what} is a file, expected a folder")
    try:
        os.listdir(path)
    except OSError as exc:
        raise ConfigError(f"{path}: {what} is not readable ({exc.strerror})") from None
    return path


def _probe(folder: Path, path: Path, what: str) -> None:
    """Create and remove a temporary file in ``folder``: the one sure test of writing."""
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".ridempc-probe-"):
            pass
    except OSError as exc:
        raise ConfigError(
            f"{path}: {what} is not writable: no file can be created in {folder} ({exc.strerror})"
        ) from None


def writable_dir(path: Path, what: str) -> Path:
    """``path`` if it is a folder that can be written, or can be created.

    A missing folder is fine when its nearest existing parent is a writable folder (the
    command creates it); a file in its place, or in place of a parent, is not.
    """
    path = Path(path)
    mode = _mode(path, what)
    if mode is not None:
        if not stat.S_ISDIR(mode):
            raise ConfigError(f"{path}: {what} is a file, expected a folder")
        _probe(path, path, what)
        return path
    parent = path.absolute().parent
    while _mode(parent, what) is None:
        parent = parent.parent
    if not stat.S_ISDIR(_mode(parent, what) or 0):
        raise ConfigError(f"{path}: {what}: its parent {parent} is a file, not a folder")
    _probe(parent, path, what)
    return path


def writable_file(path: Path, what: str) -> Path:
    """``path`` if a file can be written there: not a folder, in an existing writable folder."""
    path = Path(path)
    mode = _mode(path, what)
    if mode is not None and stat.S_ISDIR(mode):
        raise ConfigError(f"{path}: {what} is a folder, expected a file")
    if mode is not None and not stat.S_ISREG(mode):  # /dev/null would be replaced
        raise ConfigError(f"{path}: {what} is not a regular file")
    parent = path.absolute().parent
    parent_mode = _mode(parent, what)
    if parent_mode is None:
        raise ConfigError(f"{path}: {what}: its folder {parent} does not exist")
    if not stat.S_ISDIR(parent_mode):
        raise ConfigError(f"{path}: {what}: its parent {parent} is a file, not a folder")
    _probe(parent, path, what)
    return path
