"""Write ``constraints.txt``: the exact versions of ridempc's dependency closure as installed.

Run it after a change of dependencies, in an environment where the committed figures were
measured (``pip install -e ".[test,video]"``): ``python .ci/freeze_constraints.py``. The
closure is walked from ridempc's own requirements with every extra, so packages that happen to
be on the machine but that ridempc does not need are left out.
"""

from __future__ import annotations

import re
import sys
from importlib import metadata
from pathlib import Path

from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parent.parent
HEADER = """\
# Exact versions the committed figures (tests, READMEs, closing notes) were measured with.
# Used by CI and by the README's commands: pip install -c constraints.txt ...
# Regenerate with: python .ci/freeze_constraints.py
"""


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def closure(root: str, extras: set[str]) -> dict[str, str]:
    """Installed name -> version of every distribution ``root[extras]`` needs, transitively."""
    found: dict[str, str] = {}
    todo: list[tuple[str, set[str]]] = [(root, extras)]
    while todo:
        name, wanted = todo.pop()
        dist = metadata.distribution(name)
        for text in dist.requires or ():
            req = Requirement(text)
            env_ok = req.marker is None or any(
                req.marker.evaluate({"extra": extra}) for extra in (wanted or {""})
            )
            if not env_ok:
                continue
            key = _canonical(req.name)
            if key == _canonical(root):
                todo.append((root, set(req.extras)))
                continue
            try:
                version = metadata.version(req.name)
            except metadata.PackageNotFoundError:
                continue  # an optional requirement of a dependency, not installed
            if key not in found:
                found[key] = version
                todo.append((req.name, set(req.extras)))
    return found


def main() -> int:
    pins = closure("ridempc", {"test", "video"})
    lines = [f"{name}=={version}" for name, version in sorted(pins.items())]
    (ROOT / "constraints.txt").write_text(HEADER + "\n".join(lines) + "\n")
    print(f"constraints.txt: {len(lines)} packages (python {sys.version.split()[0]})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
