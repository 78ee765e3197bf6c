"""SIGINT and SIGTERM end a command at once, whichever solver is running.

The command line runs each command inside :func:`handled`: the first SIGINT or SIGTERM
raises :class:`Interrupted` in the main thread, the command unwinds (its ``finally`` blocks
remove temporary files) and ``ridempc`` exits with 128 + the signal's number (130, 143)
after one line on standard error. A further signal ends the process at once with the
same code, and a process still there ``DEADLINE_S`` after the first signal (its main
thread held in compiled code, say) is ended then (:class:`_Watcher`, the thread that takes
the signals): never a traceback, always that code.

Third-party solvers take SIGINT for themselves. While a command runs the signals are
blocked in every thread and taken by :class:`_Watcher` with ``sigwait``, so that no
solver's handler sees them; where a thread was started before (a command run inside
another program, the tests) and has them unblocked, :func:`solver_returned` (or its OSQP
form, :func:`osqp_returned`), called after each of the solvers' solves, undoes what
they did:

- **OSQP** (1.x; the C library in the ``osqp`` package is built with
  ``OSQP_ENABLE_INTERRUPT``) installs its own handler with ``sigaction`` at the start of every
  solve (``osqp_start_interrupt_listener``) and puts back, at its end, the handler it saved in
  one static variable (``osqp_end_interrupt_listener``). A SIGINT during a solve only ends
  that solve, with status ``OSQP_SIGINT`` ("interrupted"), which a controller takes for one
  failed solve. Two solves that overlap in two threads (the MPC's solver thread beside the
  whole-body QP in the control loop) save each other's handler, so OSQP's stays installed
  for good: Python never hears of a Ctrl-C again, however often it is pressed.
  :func:`osqp_returned` puts the command's handler back at the C level (``sigaction``,
  from whichever thread) and passes a SIGINT that OSQP caught on to the main thread: one
  that ended the solve, and one that arrived after OSQP's last look at its flag
  (``osqp_is_interrupted``, which the library exports), e.g. during the polish.
- **CasADi** runs Python's handler from inside IPOPT's evaluations and turns the exception
  into IPOPT's failure ``NonIpopt_Exception_Thrown`` (the interrupt would become one failed
  library entry), or into a ``SystemError`` when it lands in a conversion of CasADi's own;
  :func:`casadi_solve` raises the interrupt again once the solve has returned.

The solvers' own words about the interrupt (OSQP prints ``Solver interrupted``, CasADi a
warning line) are left out of standard output and error while a command runs.

Worker processes (``library build --jobs N``) leave signals to their parent
(:func:`worker_started`), which ends them with :func:`stop_workers`.
"""

from __future__ import annotations

import _thread
import ctypes
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Executor
from contextlib import contextmanager, suppress
from functools import cache
from types import FrameType
from typing import Any, NoReturn, TextIO, cast

__all__ = [
    "DEADLINE_S",
    "SIGNALS",
    "Handling",
    "Interrupted",
    "casadi_solve",
    "handled",
    "osqp_returned",
    "solver_returned",
    "stop_workers",
    "worker_started",
]

SIGNALS: tuple[signal.Signals, ...] = (signal.SIGINT, signal.SIGTERM)  # the ones that stop
# Bytes read and written as an opaque ``struct sigaction``: more than any platform's (152 on
# Linux x86-64), so the C library never reads or writes past the buffer.
_SIGACTION_BYTES: int = 512
# [s] from a signal to the end of a process that has not ended by itself: a ride unwinds and
# exits in 0.15-0.35 s (its cleanup in milliseconds, the rest is the interpreter's exit);
# the watcher itself may wait for the interpreter's lock and, on a loaded machine, for a
# core (0.33 s past this deadline was seen with two cores and a load of 3.5).
DEADLINE_S: float = 0.4
# Sent to the main thread with the interrupt, to end a wait it is blocked in (a lock, a
# sleep: the call fails with EINTR and Python runs the tripped handler): a signal whose
# default action is to be ignored, so a handler of its own changes nothing else.
_WAKE: signal.Signals = signal.SIGWINCH
_PR_SET_PDEATHSIG: int = 1  # prctl(2) option: the signal a process gets when its parent dies
_WORKER_JOIN_S: float = 0.2  # [s] wait for each terminated worker (SIGTERM kills at once)
_OSQP_INTERRUPTED: str = "Solver interrupted\n"  # what OSQP prints when its handler caught one
# How CasADi's messages begin, and its warnings (IPOPT's evaluation raised the interrupt:
# ``CasADi - <time> WARNING("KeyboardInterruptException") [...ipopt_nlp.cpp:132]``).
_CASADI_PREFIX: str = "CasADi - "
_CASADI_WARNING: str = " WARNING("


class Interrupted(KeyboardInterrupt):
    """A command stopped by SIGINT or SIGTERM.

    A ``KeyboardInterrupt``, so that ``except Exception`` (a controller's safe hold, a
    solver's error handling) does not take it for a failure and carry on.

    Attributes:
        signum: The signal's number.
    """

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(self.name)

    @property
    def name(self) -> str:
        """The signal's name, e.g. ``SIGINT``."""
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        """The shell's code for a process ended by the signal: 128 + its number."""
        return 128 + self.signum


@cache
def _libc() -> Any:
    """The process's C library (``sigaction``, ``prctl``)."""
    return ctypes.CDLL(None, use_errno=True)


def _disposition(signum: int) -> ctypes.Array[ctypes.c_char] | None:
    """The C-level ``struct sigaction`` of ``signum`` (opaque bytes), None where there is no
    ``sigaction`` (not POSIX)."""
    if os.name != "posix":
        return None
    action = ctypes.create_string_buffer(_SIGACTION_BYTES)
    if _libc().sigaction(signum, None, action) != 0:
        return None
    return action


class Handling:
    """The signal handling of one command (made by :func:`handled`).

    Attributes:
        unwritten: What the interrupted command leaves incomplete, for its one line, e.g.
            ``no summary.json was written in runs/x``.
        received: The first signal received, or None.
        reported: Whether the one line has been written.
    """

    def __init__(self, unwritten: str, keeps_process: bool = False) -> None:
        self.unwritten = unwritten
        self.keeps_process = keeps_process
        self.received: int | None = None
        self.reported = False
        self._action = _disposition(signal.SIGINT)  # Python's own C handler, installed by now

    def on_signal(self, signum: int, frame: FrameType | None) -> None:
        """The first signal raises :class:`Interrupted`; any further one ends the process
        (raises again where the process is kept: an interactive session)."""
        if self.received is not None and not self.keeps_process:
            self.exit_now(signum, frame)
        self.received = signum
        raise Interrupted(signum)

    def exit_now(self, signum: int, frame: FrameType | None) -> NoReturn:
        """End the process at once (a second signal during cleanup or shutdown)."""
        os._exit(self.report(signum, raw=True))

    def report(self, signum: int | None = None, raw: bool = False) -> int:
        """Write the one line (once) and return the exit code.

        Args:
            signum: The signal, if none was received (a ``KeyboardInterrupt`` raised by
                code: SIGINT).
            raw: Write to file descriptor 2 rather than through ``sys.stderr``, which the
                main thread may be in the middle of (from a signal handler).
        """
        number = self.received or signum or signal.SIGINT
        if not self.reported:
            self.reported = True
            line = f"ridempc: interrupted ({signal.Signals(number).name}); {self.unwritten}\n"
            try:
                if raw:
                    os.write(2, (("\n" if _open_progress_bar() else "") + line).encode())
                else:
                    sys.stderr.write(line)
                    sys.stderr.flush()
            except (OSError, ValueError):
                pass  # standard error closed: the exit code still says it
        return 128 + number

    def restore(self) -> None:
        """Python's C-level SIGINT handler back in place (callable from any thread)."""
        if self._action is not None:
            _libc().sigaction(signal.SIGINT, self._action, None)


_active: Handling | None = None  # the command's handling; None outside the command line


def _open_progress_bar() -> bool:
    """Whether a tqdm bar (which leaves its line unfinished) is open on standard error."""
    tqdm = getattr(sys.modules.get("tqdm"), "tqdm", None)
    return bool(getattr(tqdm, "_instances", None))  # tqdm's set of open bars


class _Watcher:
    """The thread that takes SIGINT and SIGTERM for the process while a command runs.

    Both signals are blocked in the main thread before the command starts, so in every
    thread it starts too (threads inherit the mask), and this thread takes them with
    ``sigwait``. No handler runs, neither Python's nor one a solver installed (OSQP's), and
    a signal cannot be lost in a solver's handler. The first one is passed to the main
    thread (``interrupt_main``: its Python handler raises :class:`Interrupted` as soon as
    it is back in the interpreter); a second one, or ``DEADLINE_S`` without the process
    having ended, ends it at once with the same code and line: Python runs handlers only
    in the main thread, between its bytecodes, so a long call into compiled code (CasADi
    building an NLP: 7-19 s for a Cassie entry) would otherwise hold the interrupt until it
    returns. This thread needs no more of the interpreter than such a call leaves free
    (CasADi and OSQP release its lock).
    """

    def __init__(self, handling: Handling) -> None:
        self._handling = handling
        self._closing = False
        self._mask = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
        self._thread = threading.Thread(target=self._watch, name="ridempc-signals", daemon=True)
        self._thread.start()

    def _watch(self) -> None:
        first = signal.sigwait(SIGNALS)
        if self._closing:
            return
        self._interrupt_main(first)
        while self._handling.keeps_process:  # an interactive session outlives the ride:
            again = signal.sigwait(SIGNALS)  # each signal is one more interrupt, none ends it
            if self._closing:
                return
            self._interrupt_main(again)
        if hasattr(signal, "sigtimedwait"):
            signal.sigtimedwait(SIGNALS, DEADLINE_S)  # a second one: at once
        else:
            time.sleep(DEADLINE_S)
        self._handling.exit_now(first, None)

    @staticmethod
    def _interrupt_main(signum: int) -> None:
        _thread.interrupt_main(signal.Signals(signum))
        signal.pthread_kill(threading.main_thread().ident or 0, _WAKE)  # out of a wait

    def close(self) -> None:
        """Stop watching and unblock the signals, unless one was received and the process
        is ending: then it ends at ``DEADLINE_S`` at the latest, and later signals end it at
        once."""
        ending = self._handling.received is not None and not self._handling.keeps_process
        if ending or not self._thread.is_alive():
            return
        self._closing = True
        signal.pthread_kill(self._thread.ident or 0, signal.SIGINT)  # (only it can take it)
        self._thread.join()
        signal.pthread_sigmask(signal.SIG_SETMASK, self._mask)


@contextmanager
def handled(
    unwritten: str, process_ends: bool = False, keeps_process: bool = False
) -> Iterator[Handling]:
    """SIGINT and SIGTERM raise :class:`Interrupted` in the main thread while a command runs.

    The signals are blocked and taken by :class:`_Watcher`: a second one ends the process
    at once, and whatever the main thread is doing, the process ends ``DEADLINE_S`` after
    the first at the latest, with the same code and line. On leaving, the previous handlers
    and streams are put back and the signals unblocked, unless one was received: then the
    process is ending, and the watcher keeps them (no ``KeyboardInterrupt`` can interrupt
    the interpreter's shutdown with a traceback, nor Python's reset of its handlers late in
    the shutdown let one kill it with a code other than 130/143).

    Args:
        unwritten: What an interrupted command leaves incomplete (:class:`Handling`).
        process_ends: The process ends after the command (the ``ridempc`` program): the
            signals are then ignored on leaving, also after a command that was not
            interrupted, rather than given back to Python, whose ``KeyboardInterrupt``
            would interrupt the interpreter's shutdown with a traceback.
        keeps_process: The process outlives an interrupt (an interactive session: Python's
            prompt, a Jupyter kernel): every signal raises :class:`Interrupted` in the main
            thread, none ends the process, and the previous handlers are put back on
            leaving, also after an interrupt (the solvers' threads have returned by then).

    Raises:
        RuntimeError: Not called from the main thread.
    """
    global _active
    if threading.current_thread() is not threading.main_thread():
        raise RuntimeError("signal handlers can only be installed from the main thread")
    previous = {s: signal.getsignal(s) for s in (*SIGNALS, _WAKE)}
    for s in SIGNALS:
        signal.signal(s, _dispatch)
    signal.signal(_WAKE, _woken)
    handling = Handling(unwritten, keeps_process)
    watcher = _Watcher(handling)
    streams = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Muted(sys.stdout, handling), _Muted(sys.stderr, handling)
    outer, _active = _active, handling
    try:
        yield handling
    finally:
        for muted in (sys.stdout, sys.stderr):
            if isinstance(muted, _Muted):
                with suppress(OSError, ValueError):  # a closed stream: nothing to say there
                    muted.flush()
        ending = handling.received is not None and not keeps_process
        if not ending:  # (else the solvers may still have words to say)
            sys.stdout, sys.stderr = streams
            _active = outer
        for s, handler in previous.items():  # after an interrupt the process is ending,
            if s != _WAKE and (ending or process_ends):  # by DEADLINE_S
                handler = signal.SIG_IGN
            signal.signal(s, handler)
        watcher.close()  # (unblocks the signals: the handlers are in place by now)


def _woken(signum: int, frame: FrameType | None) -> None:
    """Nothing: the signal only ends the main thread's wait (:data:`_WAKE`)."""


def _dispatch(signum: int, frame: FrameType | None) -> None:
    handling = _active
    if handling is None:  # cannot happen while installed; a plain Ctrl-C then
        raise KeyboardInterrupt
    handling.on_signal(signum, frame)


def solver_returned(caught: bool = False) -> None:
    """Call after each solve by a library that installs its own SIGINT handler (OSQP):
    puts the command's handler back and passes the interrupt on.

    Outside :func:`handled` (the package used as a library, the tests) it does nothing.

    Args:
        caught: Whether the solver reports that it caught a SIGINT (OSQP's status
            ``OSQP_SIGINT``); it is delivered to the main thread, as if it had arrived there.

    Raises:
        Interrupted: In the main thread, when a signal has been received (also one that a
            library caught and swallowed).
    """
    handling = _active
    if handling is None:
        return
    handling.restore()
    if caught and handling.received is None:  # (two solves may report the same signal)
        _thread.interrupt_main(signal.SIGINT)  # runs the handler in the main thread
    if handling.received is not None and threading.current_thread() is threading.main_thread():
        raise Interrupted(handling.received)


@cache
def _osqp() -> tuple[int, Callable[[], int] | None]:
    """OSQP's status ``OSQP_SIGINT``, and its ``osqp_is_interrupted()``: whether its handler
    caught a SIGINT since the latest solve began (None where the compiled library does not
    export it)."""
    import osqp

    try:
        from osqp import ext_builtin

        library = ctypes.CDLL(ext_builtin.__file__)
        flag = cast(Callable[[], int], library.osqp_is_interrupted)
    except (ImportError, OSError, AttributeError):
        flag = None
    return int(osqp.SolverStatus.OSQP_SIGINT), flag


def osqp_returned(status_val: int) -> None:
    """:func:`solver_returned` after an OSQP solve with status ``status_val``.

    A SIGINT that OSQP's handler caught is passed on when the solve says so (status
    ``OSQP_SIGINT``) and also when it does not: OSQP looks at its flag once per iteration,
    so a signal during the last iteration or the polish ends the solve as solved, and the
    next solve's start would clear the flag.
    """
    if _active is None:
        return
    sigint, flag = _osqp()
    solver_returned(status_val == sigint or (flag is not None and flag() != 0))


class _Muted:
    """A standard stream without the solvers' own words about an interrupt, which the
    command's line replaces: OSQP's ``Solver interrupted`` (one write) and, once a signal
    has been received, CasADi's warnings (lines CasADi writes in pieces, held until
    complete)."""

    def __init__(self, stream: TextIO, handling: Handling) -> None:
        self.stream = stream
        self._handling = handling
        self._line = ""

    def write(self, text: str) -> int:
        if text == _OSQP_INTERRUPTED:
            return len(text)
        if not (self._line or text.startswith(_CASADI_PREFIX)):
            return self.stream.write(text)
        self._line += text
        if "\n" in text:
            line, self._line = self._line, ""
            if not (_CASADI_WARNING in line and self._handling.received is not None):
                self.stream.write(line)
        return len(text)

    def flush(self) -> None:
        if self._line:  # a CasADi line that has not ended
            self.stream.write(self._line)
            self._line = ""
        self.stream.flush()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)


@contextmanager
def casadi_solve() -> Iterator[None]:
    """Around a CasADi solve (IPOPT, HPIPM; module docstring): an interrupt that CasADi
    turned into a failed solve, or into an error of its own, is raised again after it.

    Raises:
        Interrupted: A signal was received during the solve.
    """
    try:
        yield
    except Exception:
        if _active is None or _active.received is None:
            raise
    solver_returned()


def worker_started() -> None:
    """Initializer of worker processes: signals are the parent's business.

    SIGINT (a terminal sends it to the whole process group) is ignored, SIGTERM (sent by the
    parent's :func:`stop_workers`) ends the worker at once, and on Linux the worker is
    killed when its parent dies, even when the parent is killed outright.
    """
    global _active
    _active = None  # a forked copy of the parent's handling is not this process's
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)  # blocked in the parent (_Watcher)
    if sys.platform.startswith("linux"):
        _libc().prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)


def stop_workers(executor: Executor) -> None:
    """Cancel what ``executor`` has not started and end its worker processes now, without
    waiting for the solves under way (a ``ProcessPoolExecutor``; others are shut down)."""
    # The pool's worker processes: concurrent.futures has no public accessor for them.
    processes = list((getattr(executor, "_processes", None) or {}).values())
    executor.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive():
            process.terminate()
    for process in processes:
        process.join(_WORKER_JOIN_S)
