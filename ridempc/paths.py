"""Where the data folders (robots, boards, motion libraries) are, installed or in a checkout."""

from __future__ import annotations

from pathlib import Path

__all__ = ["data_root", "robots_dir", "boards_dir", "motion_library_dir", "pairs_dir"]

_PACKAGE = Path(__file__).resolve().parent


def data_root() -> Path:
    """Folder holding ``robots/``, ``boards/``, ``pairs/`` and ``motion_library/``.

    A wheel carries them inside the package (``ridempc/_data``); an editable install or a
    checkout finds them beside the package, at the repository's top level.
    """
    bundled = _PACKAGE / "_data"
    return bundled if (bundled / "robots").is_dir() else _PACKAGE.parent


def robots_dir() -> Path:
    return data_root() / "robots"


def boards_dir() -> Path:
    return data_root() / "boards"


def motion_library_dir() -> Path:
    return data_root() / "motion_library"


def pairs_dir() -> Path:
    return data_root() / "pairs"
