"""The Python API: one ride of a robot, a board, a controller and a scenario, in one call.

Example::

    import ridempc

    summary = ridempc.ride("cassie", "hovershoes", "mpc", "push", seed=3)
    print(summary["status"], summary["velocity_rmse"])

**The controller interface.** ``controller`` is a registered name (``ridempc list``) or an
instance of a subclass of :class:`ridempc.controllers.base.Controller`, built for the ride's
robot and board (``MyController(load_robot("cassie"), "hovershoes")``, with
:func:`ridempc.robots.load_robot`). Such a class:

- calls ``Controller.__init__(self, robot, board)`` (it sets ``robot``, ``board`` and
  ``command_preview``);
- sets ``rate_hz`` [Hz], how often it runs: the physics rate (1500 Hz) over a whole number;
- implements ``update(sensors, command) -> MotorCommand``: one control tick, reading only the
  :class:`~ridempc.sim.sensors.SensorPacket` (IMU, encoders in ``robot.encoder_joints`` order,
  motor torques, the latest VIO sample) and the scenario's
  :class:`~ridempc.scenarios.Command`, returning a :class:`~ridempc.sim.motors.MotorCommand`
  (torque [N m], position [rad], velocity [rad/s], kp, kd per motor, in ``robot.motors``
  order; the motor drivers apply :math:`\\tau + k_p (q^* - q) + k_d (\\dot q^* - \\dot q)`,
  cut to each motor's torque-speed curve). A non-finite command fails the ride;
- may override ``reset(sensors)`` (called once with the first packet), ``summary()`` (figures
  added to the summary), ``diagnostics()`` (scalars logged at each tick) and ``estimate()``
  (its state estimate, logged against the truth); sets ``uses_ground_truth = True`` if it
  reads ``sensors.truth`` (only filled with ``ground_truth=True``; flagged in the summary);
- may set a ``name`` (a string), which the summary's ``controller`` gives (else its class
  name).

``reset`` is called at the start of every ride, but any other state the object keeps
carries over: build a fresh object for each ride.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from numbers import Integral, Real
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ridempc.errors import ConfigError
from ridempc.interrupts import DEADLINE_S, Handling, handled
from ridempc.options import MAX_SEED

if TYPE_CHECKING:
    from ridempc.controllers.base import Controller
    from ridempc.scenarios import Scenario

__all__ = ["ride"]


def ride(
    robot: str,
    board: str,
    controller: str | Controller,
    scenario: str | Path | Scenario = "stand-still",
    *,
    seed: int = 0,
    out: str | Path | None = None,
    duration: float | None = None,
    ground_truth: bool = False,
    plots: bool = False,
) -> dict[str, Any]:
    """Ride once; return the summary, the same keys as ``summary.json``.

    Everything is checked before anything is simulated or written, as for ``ridempc sim``.

    Args:
        robot: Robot name, or ``none`` for a dead weight (with controller ``dead-weight``).
        board: Board name, ``none`` for flat ground.
        controller: A registered controller name, or an object implementing the package's
            controller interface (module docstring) built for ``robot`` on ``board``.
        scenario: A library name (the board's variant where there is one), the path of a
            scenario file (a :class:`~pathlib.Path`, or a string ending in ``.toml`` or
            holding a ``/``), or a :class:`~ridempc.scenarios.Scenario`.
        seed: Seed of the sensor noise, in [0, 2**32 - 1].
        out: Output folder: exactly what ``ridempc sim --out`` writes (``log.npz``,
            ``summary.json``; ``plots.png`` only with ``plots``), the files an earlier run
            wrote there replaced. None: nothing is written at all, no folder is checked.
        duration: Override of the scenario's duration [s], in [0.01, 3600], or None.
        ground_truth: Give the controller ground truth (debugging only; flagged in the
            summary).
        plots: With ``out``, also write ``plots.png``.

    Returns:
        The summary: ``status`` (``ok``, ``fell``, ``failed``), ``fell``, ``fall_time_s``,
        the tracking errors and the controller's figures (README, "What a run writes");
        ``files`` lists what was written (empty without ``out``).

    Raises:
        UnknownNameError: A robot, board, controller or scenario name that does not exist.
        ConfigError: Any other bad input (named with its value and what is allowed).
        Interrupted: SIGINT or SIGTERM during the ride. In an interactive session (Python's
            prompt, a Jupyter kernel) it is raised and the session goes on, ready for the
            next ride; the solvers' signal handlers are undone. Called from a script's main thread
            with Python's own SIGINT handler in place, the ride takes the signals as
            ``ridempc sim`` does (:func:`ridempc.interrupts.handled`): the script's
            ``finally`` blocks run, and the process ends with the command's one line and
            code 130 or 143, at once if the script does not catch the interrupt, else
            ``DEADLINE_S`` (0.4 s) after the signal. Elsewhere (the command line, a worker
            process, another thread) the caller's handling stands.
    """
    from ridempc.run import RideRequest
    from ridempc.run import ride as ride_request

    _check_plain(robot=robot, board=board)
    if not _is_int(seed) or not 0 <= seed <= MAX_SEED:
        raise ConfigError(f"seed {seed!r}: allowed: an integer in [0, {MAX_SEED}]")
    if duration is not None and (not _is_number(duration)):
        raise ConfigError(f"duration {duration!r}: allowed: seconds as a number, or None")
    if not isinstance(out, str | Path | None):
        raise ConfigError(f"out {out!r}: allowed: a folder path, or None")
    if isinstance(scenario, str) and not scenario:
        raise ConfigError("scenario '': allowed: a library name, a .toml path or a Scenario")
    request = RideRequest(
        robot=robot,
        board=board,
        controller=controller,
        scenario=scenario,
        out=None if out is None else Path(out),
        duration=None if duration is None else float(duration),
        seed=int(seed),
        plots=plots and out is not None,
        ground_truth=bool(ground_truth),
        option_style="{}",
    )
    where = f"no summary.json was written in {out}" if out is not None else "no summary returned"
    with _signals_taken(where):
        return ride_request(request)


def _is_int(value: object) -> bool:
    """An integer, NumPy's too, never a bool."""
    return isinstance(value, Integral) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    """A real number, NumPy's too, never a bool."""
    return isinstance(value, Real) and not isinstance(value, bool)


def _check_plain(**names: object) -> None:
    for what, value in names.items():
        if not isinstance(value, str):
            raise ConfigError(f"{what} {value!r}: allowed: a name (a string), see ridempc list")


@contextmanager
def _signals_taken(unwritten: str) -> Iterator[None]:
    """SIGINT and SIGTERM raise :class:`~ridempc.interrupts.Interrupted` during the ride,
    where no one else takes them (see :func:`ride`).

    The process then ends as ``ridempc`` does, with the command's one line and code: an
    interrupt the script does not catch at once, instead of a traceback
    (:data:`sys.excepthook`), one it catches ``DEADLINE_S`` after it. (The signal watcher
    would end it then too, but only when the signal reaches the watcher's thread: threads
    that libraries started on import, before the ride blocked the signals, may take it.)
    """
    ours = (
        threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    )
    if not ours:
        yield
        return
    if _interactive():
        with handled(unwritten, keeps_process=True):
            yield
        return
    with handled(unwritten) as handling:
        try:
            yield
        except KeyboardInterrupt:
            if handling.received is not None:
                sys.excepthook = _ends_quietly(handling, sys.excepthook)
                ending = threading.Timer(DEADLINE_S, handling.exit_now, (handling.received, None))
                ending.daemon = True
                ending.start()
            raise


def _interactive() -> bool:
    """Whether the process is an interactive session, which must outlive an interrupt:
    Python's prompt (``sys.ps1``, ``python -i``) or a Jupyter/IPython kernel."""
    return hasattr(sys, "ps1") or bool(sys.flags.interactive) or "ipykernel" in sys.modules


def _ends_quietly(handling: Handling, previous: Callable[..., Any]) -> Callable[..., Any]:
    """An exception hook that ends the process on an uncaught interrupt with the command's
    line and code (:meth:`~ridempc.interrupts.Handling.report`), and leaves any other
    exception to ``previous``."""

    def hook(kind: type[BaseException], value: BaseException, trace: Any) -> None:
        if not issubclass(kind, KeyboardInterrupt):
            previous(kind, value, trace)
            return
        code = handling.report()
        for stream in (sys.stdout, sys.stderr):
            with suppress(OSError, ValueError):
                stream.flush()
        os._exit(code)  # as the command: a solver's thread may still be in compiled code

    return hook
