"""Where a sweep's rides run: a local process pool (the default), or a Dask cluster.

Both are :class:`Engine` objects handing out ``concurrent.futures`` futures, so the runner
(:mod:`ridempc.sweep.runner`) is the same for both.

- ``local``: a ``ProcessPoolExecutor`` of ``--workers`` processes started with
  :func:`~ridempc.interrupts.worker_started` (signals are the command's business; a worker
  dies with its parent). A worker that dies breaks the pool: :meth:`LocalEngine.replace`
  starts a new one, and the runner submits again what was under way.
- ``dask`` (``pip install "ridempc[cluster]"``): without ``--address``, a local cluster of
  ``--workers`` single-threaded worker processes; with it, the scheduler at that address.
  A worker that dies is restarted by its nanny and its task rescheduled by Dask itself
  (up to Dask's ``allowed-failures``, then the ride is recorded as failed).

Why Dask rather than Ray (measured on the 2-core development machine, 2 workers, Python
3.11, distributed 2026.8.0, Ray 2.60.0; ``docs/sweeps.md`` has the commands and the table):
a local Dask cluster starts in 1.5 s against Ray's 4.0 s, it and its workers hold 0.2 GiB
against Ray's 0.8 GiB (raylet, GCS server, agents), and it installs 24 MB against Ray's
240 MB; the per-task overhead of both (2.5 ms and 0.9 ms for a trivial task, 0.06 s and
0.08 s per 1.5 s ride) is nothing beside a ride. Its executor hands out standard
``concurrent.futures`` futures, so the runner needs nothing of Dask's own.
"""

from __future__ import annotations

import logging
import sys
import threading
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from contextlib import suppress
from typing import Any, Protocol, TypeVar

from ridempc.errors import ConfigError
from ridempc.interrupts import stop_workers, worker_started

__all__ = ["CONNECT_TIMEOUT_S", "ENGINES", "DaskEngine", "Engine", "LocalEngine", "make_engine"]

T = TypeVar("T")

ENGINES: tuple[str, ...] = ("local", "dask")
# [s] to reach a scheduler given by --address: a live one on a LAN answers in milliseconds.
CONNECT_TIMEOUT_S: float = 5.0
# [s] for a cluster to close on an interrupt: within the command's second.
_STOP_S: float = 0.2
# The resource tracker's warning of semaphores it removes because their process was ended.
_QUIET_TRACKER: str = "ignore::UserWarning:multiprocessing.resource_tracker"
_CLUSTER_HINT = 'pip install "ridempc[cluster]"'


class Engine(Protocol):
    """What the runner needs of an engine.

    Attributes:
        name: ``local`` or ``dask``.
        slots: Rides that run at once (the runner submits no more than that).
        broken: The exceptions a future raises when its worker died and the engine must be
            replaced (:meth:`replace`) before anything more is submitted.
    """

    name: str
    slots: int
    broken: tuple[type[BaseException], ...]

    def submit(self, fn: Callable[..., T], *args: Any) -> Future[T]:
        """Run ``fn(*args)`` on a worker."""

    def replace(self) -> None:
        """Start afresh after a worker died (every future under way is then lost)."""

    def stop(self) -> None:
        """End now, without waiting for the rides under way (an interrupt, an error)."""

    def close(self) -> None:
        """End after the last ride."""


class LocalEngine:
    """A process pool on this machine (module docstring)."""

    name = "local"
    broken: tuple[type[BaseException], ...] = (BrokenProcessPool,)

    def __init__(self, workers: int) -> None:
        self.slots = workers
        self._pool = self._start()

    def _start(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(max_workers=self.slots, initializer=worker_started)

    def submit(self, fn: Callable[..., T], *args: Any) -> Future[T]:
        return self._pool.submit(fn, *args)

    def replace(self) -> None:
        stop_workers(self._pool)
        self._pool = self._start()

    def stop(self) -> None:
        stop_workers(self._pool)

    def close(self) -> None:
        self._pool.shutdown(wait=True)


class DaskEngine:
    """A Dask cluster: a local one of ``workers`` processes, or the one at ``address``."""

    name = "dask"
    broken: tuple[type[BaseException], ...] = ()  # Dask replaces dead workers itself

    def __init__(self, workers: int, address: str | None) -> None:
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError:
            raise ConfigError(
                f"--engine dask: Dask is not installed; allowed: {_CLUSTER_HINT}, or --engine local"
            ) from None
        self._cluster = None
        _start_resource_tracker()
        if address is None:
            self._cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,  # one ride per process, as in the local pool
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            )
            self._client = Client(self._cluster)
        else:
            try:
                self._client = Client(address, timeout=CONNECT_TIMEOUT_S)
            except (OSError, TimeoutError, ValueError) as exc:
                reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                raise ConfigError(
                    f"--address {address}: no Dask scheduler answered within "
                    f"{CONNECT_TIMEOUT_S:g} s ({reason}); allowed: the address of a running "
                    "scheduler, e.g. tcp://10.0.0.5:8786"
                ) from None
        self.slots = max(1, sum(self._client.nthreads().values()))
        self._executor = self._client.get_executor(pure=False)  # a ride twice: run it twice

    def submit(self, fn: Callable[..., T], *args: Any) -> Future[T]:
        return self._executor.submit(fn, *args)

    def replace(self) -> None:
        """Nothing to do: the nanny restarts a dead worker."""

    def stop(self) -> None:
        """Close without waiting for the rides under way: a local cluster's workers are
        killed with it, an existing cluster's workers drop the tasks of a gone client."""
        with suppress(Exception):  # the process is ending: nothing to add to its line
            self._client.close(timeout=_STOP_S)
            if self._cluster is not None:
                self._cluster.close(timeout=_STOP_S)

    def close(self) -> None:
        self._client.close()
        if self._cluster is not None:
            self._cluster.close()


def _start_resource_tracker() -> None:
    """Start multiprocessing's resource tracker from a thread that then ends.

    The thread that starts the tracker is left with SIGINT and SIGTERM unblocked
    (``resource_tracker.ensure_running`` blocks them around the spawn, then unblocks them).
    Started by Dask's event-loop thread, that thread would take the signals meant for the
    command's watcher (:mod:`ridempc.interrupts`).
    """
    from multiprocessing import resource_tracker

    if _QUIET_TRACKER not in sys.warnoptions:  # passed on to the tracker as its -W flag
        sys.warnoptions.append(_QUIET_TRACKER)
    starter = threading.Thread(target=resource_tracker.ensure_running, name="ridempc-tracker")
    starter.start()
    starter.join()


def make_engine(name: str, workers: int, address: str | None) -> Engine:
    """The engine ``name`` (one of :data:`ENGINES`).

    Raises:
        ConfigError: An unknown engine, ``--address`` with the local engine, an engine that
            is not installed, or an address where no scheduler answers.
    """
    if name not in ENGINES:
        raise ConfigError(f"--engine {name}: allowed: {', '.join(ENGINES)}")
    if name == "local":
        if address is not None:
            raise ConfigError(
                f"--address {address}: the local engine has no address; allowed: "
                "--engine dask with --address"
            )
        return LocalEngine(workers)
    return DaskEngine(workers, address)
