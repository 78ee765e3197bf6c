"""CasADi functions compiled to C once and cached: the MPC's Jacobians at C speed.

:func:`compiled` turns a CasADi function into the same function built by the C compiler
(CasADi's code generation, ``gcc -O2``), loaded through ``casadi.external``. The build is
cached in :func:`cache_dir` under the function's name and key: a SHA-256 of the
function's serialised expression graph, CasADi's version and the compiler's command, so
that another version of the model (another robot, board or library entry) gets a build
of its own. The key is compiled into the library too (a string constant), and a cached
file whose bytes do not hold its key (a build from another version, or a truncated one)
is rebuilt, never loaded. Each build is written beside its final name and renamed, so a
reader never sees half a library.

The generated code performs the virtual machine's operations in the same order (no
``-ffast-math``, no fused multiply-add on the default x86-64 target), so its results are
the same to the bit. Where no compiler is found, or the build fails, the function is
returned as it was (CasADi's virtual machine) after one warning line on standard error.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from functools import cache
from pathlib import Path

import casadi as ca

__all__ = ["CACHE_ENV", "COMPILER_ENV", "cache_dir", "compiled", "library_path"]

CACHE_ENV: str = "RIDEMPC_CODEGEN_CACHE"  # the cache folder, over ~/.cache/ridempc/codegen
COMPILER_ENV: str = "RIDEMPC_CC"  # the C compiler, over gcc (empty: none, the Python path)
_FLAGS: tuple[str, ...] = ("-O2", "-fPIC", "-shared")  # -O3 built 2x slower, ran no faster
_BUILD_TIMEOUT_S: float = 120.0  # the largest model (the dog's) builds in about 3 s
_KEY_PREFIX: str = "ridempc-codegen-key:"


def cache_dir() -> Path:
    """The folder the builds are cached in: ``$RIDEMPC_CODEGEN_CACHE``, else
    ``$XDG_CACHE_HOME/ridempc/codegen`` (``~/.cache`` by default)."""
    folder = os.environ.get(CACHE_ENV)
    if folder:
        return Path(folder)
    root = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(root) / "ridempc" / "codegen"


def _compiler() -> str | None:
    """The C compiler's path (``$RIDEMPC_CC`` or gcc), None if there is none."""
    name = os.environ.get(COMPILER_ENV, "gcc")
    return shutil.which(name) if name else None


def _key(function: ca.Function, compiler: str) -> str:
    text = "\n".join([ca.CasadiMeta.version(), compiler, *_FLAGS, function.serialize()])
    return hashlib.sha256(text.encode()).hexdigest()


def library_path(function: ca.Function, folder: Path, key: str) -> Path:
    """Where ``function``'s build with ``key`` is cached in ``folder``."""
    return folder / f"{function.name()}-{key[:16]}.so"


def _holds_key(library: Path, key: str) -> bool:
    """Whether ``library`` exists and its bytes hold ``key`` (module docstring)."""
    try:
        return (_KEY_PREFIX + key).encode() in library.read_bytes()
    except OSError:
        return False


@cache
def _warn(message: str) -> None:
    """One warning line on standard error, once per process and message."""
    print(f"ridempc: warning: {message}", file=sys.stderr, flush=True)


def _build(function: ca.Function, compiler: str, key: str, library: Path) -> str | None:
    """Generate, compile and place ``function``'s library; None, or why it failed."""
    try:
        library.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=library.parent, prefix=".build-") as build:
            source = f"{function.name()}.c"
            generator = ca.CodeGenerator(source, {"with_header": False})
            generator.add(function)
            generator.generate(build + os.sep)
            with open(Path(build) / source, "a", encoding="utf-8") as stream:
                stream.write(f'\nconst char ridempc_codegen_key[] = "{_KEY_PREFIX}{key}";\n')
            built = Path(build) / "library.so"
            run = subprocess.run(
                [compiler, *_FLAGS, "-o", str(built), str(Path(build) / source)],
                capture_output=True,
                text=True,
                timeout=_BUILD_TIMEOUT_S,
                check=False,
            )
            if run.returncode != 0:
                first = (run.stderr.strip().splitlines() or ["no message"])[0]
                return f"{Path(compiler).name} exited with {run.returncode}: {first[:120]}"
            os.replace(built, library)
    except (OSError, subprocess.SubprocessError, RuntimeError) as exc:
        return " ".join(f"{type(exc).__name__}: {exc}".split())[:160]
    return None


def compiled(function: ca.Function, folder: Path | None = None) -> ca.Function:
    """``function`` built by the C compiler, from the cache or built now (module
    docstring); ``function`` itself, after one warning line, where it cannot be.

    Args:
        function: A CasADi function (SX or MX, maps included).
        folder: The cache folder (default :func:`cache_dir`).
    """
    compiler = _compiler()
    if compiler is None:
        _warn(
            "no C compiler found (gcc, or $RIDEMPC_CC): the MPC's Jacobians run in CasADi's "
            "virtual machine, slower"
        )
        return function
    key = _key(function, compiler)
    library = library_path(function, folder or cache_dir(), key)
    if not _holds_key(library, key):
        failure = _build(function, compiler, key, library)
        if failure is not None or not _holds_key(library, key):
            _warn(
                f"building {function.name()} in {library.parent} failed "
                f"({failure or 'its key is not in the library'}): CasADi's virtual machine "
                "evaluates it, slower"
            )
            return function
    return ca.external(function.name(), str(library))
