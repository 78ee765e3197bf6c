"""The ``ridempc`` command's entry point (also ``python -m ridempc``).

SIGINT and SIGTERM are blocked here, before anything is imported: libraries start threads
on import (NumPy's OpenBLAS pool), and a thread inherits the signal mask of the thread that
starts it, so with the signals blocked first no such thread can take one, and every signal
reaches :mod:`ridempc.interrupts`' watcher. A signal that comes during the imports waits,
pending, until the watcher takes it (the command then stops at once with 130 or 143).
"""

from __future__ import annotations

import signal
import sys

__all__ = ["main"]


def main() -> None:
    """Run the ``ridempc`` command (:func:`ridempc.cli.main`) and exit with its code."""
    signal.pthread_sigmask(signal.SIG_BLOCK, (signal.SIGINT, signal.SIGTERM))
    from ridempc.cli import main as command

    sys.exit(command())


if __name__ == "__main__":
    main()
