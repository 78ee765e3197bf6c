"""The thread the MPC's solves run in beside the control loop.

A daemon thread, unlike a ``ThreadPoolExecutor``'s worker (which the interpreter waits for
at exit): after an interrupt the process ends at once, even while OSQP is still iterating
on a solve that nobody will read.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any, TypeVar

__all__ = ["SolverThread"]

T = TypeVar("T")


class SolverThread:
    """Runs submitted calls one after another in a daemon thread, started at the first.

    Args:
        name: The thread's name.
    """

    def __init__(self, name: str) -> None:
        self.name = name
        self._calls: queue.SimpleQueue[tuple[Future[Any], Callable[[], Any]]] = queue.SimpleQueue()
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()

    def submit(self, call: Callable[[], T]) -> Future[T]:
        """Queue ``call``; its result (or exception) arrives through the future."""
        future: Future[T] = Future()
        self._calls.put((future, call))
        with self._lock:
            if self._thread is None or not self._thread.is_alive():  # also after a fork
                self._thread = threading.Thread(target=self._work, name=self.name, daemon=True)
                self._thread.start()
        return future

    def _work(self) -> None:
        while True:
            future, call = self._calls.get()
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(call())
            except BaseException as exc:  # noqa: BLE001 - handed to the caller through the future
                future.set_exception(exc)
