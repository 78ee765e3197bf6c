"""``ridempc margin``: the largest push on the base a rider survives, in each direction.

Each direction is searched on its own (:func:`~ridempc.sweep.bisection.find_margin`, where
the monotonicity assumption is stated), its rides one after another; the directions, and
one ride without a push, run in parallel over worker processes. Every ride goes through
:func:`ridempc.api.ride` with a scenario built in code (:mod:`ridempc.sweep.pushes`), so
nothing is written for it; the command writes the results (:mod:`ridempc.sweep.margin_files`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from functools import partial
from typing import Any

from ridempc.errors import ConfigError, RidempcError, UnknownNameError
from ridempc.interrupts import stop_workers, worker_started
from ridempc.scenarios import Scenario
from ridempc.sweep.bisection import Margin, Outcome, Search, find_margin
from ridempc.sweep.pushes import directions, pushed_scenario

__all__ = [
    "MarginResult",
    "MarginSpec",
    "RidePush",
    "check_spec",
    "outcome_of",
    "ride_pushed",
    "run_margin",
]


@dataclass(frozen=True)
class MarginSpec:
    """What ``ridempc margin`` measures.

    Attributes:
        robot: Robot name.
        board: Board name.
        controller: Controller name.
        scenario: The scenario pushed (checked).
        seed: The seed of every ride (sensor noise).
        directions: Number of push directions, evenly spaced.
        push_time: When the push starts [s].
        duration_after: Ridden after the push starts [s].
        search: Tolerance, first push, cap and check rides of each direction's search.
    """

    robot: str
    board: str
    controller: str
    scenario: Scenario
    seed: int
    directions: int
    push_time: float
    duration_after: float
    search: Search

    def pushed(self, degrees: float, magnitude: float) -> Scenario:
        """The scenario of one ride (magnitude 0: the unpushed ride)."""
        return pushed_scenario(
            self.scenario, degrees, magnitude, self.push_time, self.duration_after
        )


# One ride: (spec, direction [deg], magnitude [N/kg]) -> how it ended.
RidePush = Callable[[MarginSpec, float, float], Outcome]


@dataclass(frozen=True)
class MarginResult:
    """Every direction's search and the unpushed ride.

    Attributes:
        spec: What was measured.
        unpushed: The ride without a push.
        margins: Each direction's search, by direction [deg], counter-clockwise from 0.
        wall_time_s: Wall-clock time of all the rides [s].
    """

    spec: MarginSpec
    unpushed: Outcome
    margins: dict[float, Margin]
    wall_time_s: float = 0.0

    @property
    def failed(self) -> int:
        """Rides that failed (errors, not falls)."""
        own = int(self.unpushed.status == "failed")
        return own + sum(m.failed for m in self.margins.values())


def outcome_of(summary: dict[str, Any]) -> Outcome:
    """A ride's outcome from its summary (``status`` ``ok``, ``fell`` or ``failed``)."""
    return Outcome(summary["status"], summary.get("fall_time_s"), summary.get("error"))


def ride_pushed(spec: MarginSpec, degrees: float, magnitude: float) -> Outcome:
    """Ride one push through :func:`ridempc.api.ride`, writing nothing.

    An error the ride raises (a controller's, the physics') is its outcome ``failed``,
    so that one ride does not end the other directions' searches; bad input cannot reach
    here (:func:`check_spec` ran first) and is raised.
    """
    from ridempc.api import ride

    try:
        summary = ride(
            spec.robot,
            spec.board,
            spec.controller,
            spec.pushed(degrees, magnitude),
            seed=spec.seed,
            out=None,
        )
    except (ConfigError, UnknownNameError):
        raise
    except Exception as exc:  # a crashed ride is recorded, not fatal (issue 38)
        return Outcome("failed", error=f"{type(exc).__name__}: {exc}")
    return outcome_of(summary)


def _search(spec: MarginSpec, degrees: float, ride: RidePush) -> Margin:
    """One direction's search (in a worker process)."""
    return find_margin(partial(ride, spec, degrees), spec.search)


class _Inline:
    """An executor that runs each task at once, in this process (one worker)."""

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        future: Future[Any] = Future()
        future.set_result(fn(*args))
        return future

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        pass


def run_margin(spec: MarginSpec, workers: int, ride: RidePush | None = None) -> MarginResult:
    """Search every direction of ``spec`` and ride once without a push.

    Args:
        spec: What to measure (checked).
        workers: Worker processes (1: every ride in this process).
        ride: Rides one push (default :func:`ride_pushed`; the tests give a fake one).

    Returns:
        Every direction's search and the unpushed ride.

    Raises:
        RidempcError: A worker process died (its direction is lost).
        Interrupted: SIGINT or SIGTERM; the workers are ended at once.
    """
    ride = ride or ride_pushed
    started = time.monotonic()
    angles = directions(spec.directions)
    executor: Any = (
        _Inline()
        if workers == 1
        else ProcessPoolExecutor(
            max_workers=min(workers, len(angles) + 1), initializer=worker_started
        )
    )
    try:
        unpushed: Future[Outcome] = executor.submit(ride, spec, 0.0, 0.0)
        searches = {executor.submit(_search, spec, a, ride): a for a in angles}
        pending: set[Future[Any]] = {unpushed, *searches}
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                future.result()  # an error raises now, not after the other directions
        margins = {searches[f]: f.result() for f in searches}
        wall_time = time.monotonic() - started
        return MarginResult(spec, unpushed.result(), dict(sorted(margins.items())), wall_time)
    except BrokenProcessPool as exc:
        raise RidempcError(f"a worker process died ({exc}); no margin.json was written") from None
    except BaseException:  # an interrupt: the rides under way are not waited for
        if not isinstance(executor, _Inline):
            stop_workers(executor)
        raise
    finally:
        executor.shutdown(cancel_futures=True)


def check_spec(spec: MarginSpec) -> None:
    """Everything a ride of ``spec`` needs, checked before any ride: the names, the pair,
    and the scenario with the largest push against the built scene
    (:func:`ridempc.run.check_request`, as ``ridempc sim`` checks; ~1-2 s).

    Raises:
        UnknownNameError: A robot, board or controller that does not exist, or a pair the
            controller does not ride.
        ConfigError: A scenario that does not apply to the pair or its scene, or that the
            push makes invalid (a base event after the shortened ride's end).
    """
    from ridempc.run import RideRequest, check_request

    if not spec.scenario.applies_to(spec.robot, spec.board):  # named as the user gave it
        raise ConfigError(
            f"--scenario {spec.scenario.name}: does not apply to {spec.robot} on board "
            f"'{spec.board}'"
        )
    check_request(
        RideRequest(
            robot=spec.robot,
            board=spec.board,
            controller=spec.controller,
            scenario=spec.pushed(0.0, spec.search.cap),
            out=None,
            seed=spec.seed,
        )
    )
