"""The process the MPC's problems are built and solved in beside the control loop.

A thread does not take the MPC off the control tick: building a problem is mostly small
NumPy and CasADi calls that hold Python's lock (only OSQP's iterations release it), so the
loop's ticks wait for it all the same. :class:`SolverProcess` forks the process once, at its
first :meth:`~SolverProcess.submit`: the child is a copy of the rider as it stands then
(its MPC, QP and warm start, its problem shapers) and from then on builds and solves each
problem it is sent, on the second core, while the loop ticks on. Each reply is read at a
fixed tick (:meth:`Reply.result`), so a ride does not depend on how fast the child runs.

The child leaves signals to its parent (:func:`~ridempc.interrupts.worker_started`: SIGINT
ignored, killed when the parent dies) and ends when its pipe closes: at
:meth:`~SolverProcess.close`, when the object is collected, or with the parent.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import threading
import time
import weakref
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any, Generic, NoReturn, TypeVar

from ridempc.errors import RidempcError
from ridempc.interrupts import worker_started

__all__ = ["Reply", "SolverProcess", "forks"]

I = TypeVar("I")  # noqa: E741 - what is sent
R = TypeVar("R")  # what comes back
_REAP_S: float = 0.2  # [s] wait for the child to end after its pipe closes, then SIGKILL


def forks() -> bool:
    """Whether this process may fork a solver process: POSIX, in the main thread (the
    child's signal setup needs it) and not itself a worker of a pool (a sweep's rides run
    one per worker already, the cores are taken)."""
    return (
        hasattr(os, "fork")
        and threading.current_thread() is threading.main_thread()
        and multiprocessing.parent_process() is None
    )


class Reply(Generic[R]):
    """The answer to one :meth:`SolverProcess.submit`, read once with :meth:`result`."""

    def __init__(self, owner: SolverProcess[Any, R]) -> None:
        self._owner = owner

    def result(self) -> R:
        """Wait for the child's answer.

        Raises:
            Exception: What the work raised in the child (a ``RidempcError`` naming it
                where it could not be sent).
            RidempcError: The child died.
        """
        return self._owner._receive()


class SolverProcess(Generic[I, R]):
    """Runs ``work`` on each submitted item, in order, in a child forked at the first.

    Args:
        work: Called in the child with each item; its result (or exception) is sent back.
            A bound method works on the child's copy of its object.
    """

    def __init__(self, work: Callable[[I], R]) -> None:
        self._work = work
        self._conn: Connection | None = None
        self._pid = 0
        self._finalizer: weakref.finalize | None = None

    def submit(self, item: I) -> Reply[R]:
        """Send ``item`` (forking the child first, if not yet); read its answer through
        the reply, before the next submit."""
        if self._conn is None:
            self._start()
        assert self._conn is not None
        try:
            self._conn.send(item)
        except OSError as exc:  # the child is gone
            self._ended(exc)
        return Reply(self)

    def _start(self) -> None:
        parent, child = multiprocessing.Pipe()
        pid = os.fork()
        if pid == 0:  # the child: never returns into the parent's stack
            try:
                parent.close()
                worker_started()
                _serve(child, self._work)
            finally:
                os._exit(0)
        child.close()
        self._conn, self._pid = parent, pid
        self._finalizer = weakref.finalize(self, _stop, parent, pid)

    def _receive(self) -> R:
        assert self._conn is not None
        try:
            ok, value = self._conn.recv()
        except (EOFError, OSError) as exc:
            self._ended(exc)
        if not ok:
            raise value
        return value

    def _ended(self, exc: BaseException) -> NoReturn:
        self.close()
        raise RidempcError(f"the MPC's solver process ended ({exc!r})") from None

    def close(self) -> None:
        """End the child (its pipe closed, then killed if still there)."""
        if self._finalizer is not None:
            self._finalizer()
        self._conn, self._finalizer = None, None


def _serve(conn: Connection, work: Callable[[Any], Any]) -> None:
    """The child's loop: each item received, worked on, its result or exception sent."""
    while True:
        try:
            item = conn.recv()
        except (EOFError, OSError):
            return
        try:
            reply: tuple[bool, Any] = (True, work(item))
        except Exception as exc:  # noqa: BLE001 - handed to the parent
            reply = (False, exc)
        try:
            conn.send(reply)
        except (pickle.PicklingError, TypeError, AttributeError):
            conn.send((False, RidempcError(f"{type(reply[1]).__name__}: {reply[1]}")))
        except (BrokenPipeError, OSError):
            return


def _stop(conn: Connection, pid: int) -> None:
    """Close the child's pipe (it ends at once) and reap it, killing it if it lingers."""
    conn.close()
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if done == 0:
            _wait_or_kill(pid)
    except ChildProcessError:
        pass  # reaped already


def _wait_or_kill(pid: int) -> None:
    deadline = time.monotonic() + _REAP_S
    while time.monotonic() < deadline:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if done:
            return
        time.sleep(0.005)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
