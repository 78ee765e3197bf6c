"""The largest push a rider survives in one direction, by bracketing and bisection.

**Monotonicity assumption**: a rider that survives a push of magnitude :math:`x` [N/kg]
survives every smaller push in the same direction. Under it, the outcomes along the
magnitude axis are *survived* up to one boundary :math:`x^*` and *fell* above it, and
bisection finds :math:`x^*` to a tolerance :math:`\\epsilon` in
:math:`\\lceil \\log_2 (x_{hi} - x_{lo}) / \\epsilon \\rceil` rides.

The search (:func:`find_margin`):

1. **Bracket**: ride :math:`x = x_0, 2 x_0, 4 x_0, \\dots` (at most the cap) until one
   falls: the last survivor is :math:`x_{lo}` (0, unridden, if the first falls), the fall
   :math:`x_{hi}`. A rider that survives the cap has a margin of at least the cap.
2. **Bisect**: ride the midpoint of :math:`[x_{lo}, x_{hi}]` and keep the half the boundary
   is in, until :math:`x_{hi} - x_{lo} \\le \\epsilon`. The boundary is :math:`x_{lo}`.
3. **Check**: bisection only ever rides between a survivor and a fall, so its rides agree
   with a single boundary whether or not the assumption holds. Where it fails (a weaker
   push that lands at a worse moment of the rider's sway), bisection finds *a* boundary, not
   necessarily the lowest: ``checks`` further rides look for a fall below it, each in the
   middle of the widest gap between the pushes ridden in :math:`[0, x_{lo}]`. A fall there
   marks the direction non-monotone and the margin becomes the largest survived push below
   the lowest fall. A band of falls narrower than the gaps left can still go unseen.

A ride that fails (an error, not a fall) is not counted as survived: the search treats it
as a fall and records it as ``failed``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

__all__ = [
    "MAGNITUDE_DIGITS",
    "Margin",
    "Outcome",
    "Search",
    "Trial",
    "find_margin",
]

# Magnitudes ridden are rounded to 1 mN/kg: a hundredth of the finest tolerance allowed, and
# short enough to name a ride's scenario file and to read in margin.json.
MAGNITUDE_DIGITS: int = 3


@dataclass(frozen=True)
class Outcome:
    """How one ride ended.

    Attributes:
        status: ``ok``, ``fell`` or ``failed`` (the ride's summary status).
        fall_time_s: When the rider fell [s], or None.
        error: Why the ride failed, or None.
    """

    status: str
    fall_time_s: float | None = None
    error: str | None = None

    @property
    def survived(self) -> bool:
        return self.status == "ok"


@dataclass(frozen=True)
class Trial:
    """One ride of the search.

    Attributes:
        magnitude: The push [N/kg].
        phase: ``bracket``, ``bisect`` or ``check``.
        outcome: How it ended.
    """

    magnitude: float
    phase: str
    outcome: Outcome

    @property
    def survived(self) -> bool:
        return self.outcome.survived


@dataclass(frozen=True)
class Search:
    """How the boundary is searched for.

    Attributes:
        tolerance: Bisection stops when the bracket is this narrow [N/kg].
        start: The first push of the bracket [N/kg].
        cap: The largest push ridden [N/kg].
        checks: Rides below the boundary that look for a non-monotone outcome.
    """

    tolerance: float
    start: float
    cap: float
    checks: int


@dataclass(frozen=True)
class Margin:
    """The search's result in one direction.

    Attributes:
        margin: The largest push survived with no smaller push fallen [N/kg] (the cap if
            none fell).
        boundary: Where bisection ended: the largest survivor below its bracketing fall [N/kg].
        lowest_fall: The smallest push that fell or failed [N/kg], None if none did.
        capped: Nothing up to the cap fell: the margin is at least the cap.
        monotone: No push fell below one that was survived.
        trials: Every ride, in the order ridden.
    """

    margin: float
    boundary: float
    lowest_fall: float | None
    capped: bool
    monotone: bool
    trials: tuple[Trial, ...]

    @property
    def failed(self) -> int:
        """Rides that failed (errors, not falls)."""
        return sum(1 for t in self.trials if t.outcome.status == "failed")


def _rounded(x: float) -> float:
    return round(x, MAGNITUDE_DIGITS)


def find_margin(ride: Callable[[float], Outcome], search: Search) -> Margin:
    """Bracket, bisect and check the largest survivable push (module docstring).

    Assumes monotonicity: a rider that survives a push survives every smaller one, so that
    one boundary separates the survived pushes from the fallen ones and bisection finds it;
    the check rides report where that fails rather than prove that it holds.

    Args:
        ride: Rides one push of the given magnitude [N/kg] and says how it ended.
        search: Tolerance, first push, cap and check rides.

    Returns:
        The margin and every ride.
    """
    trials: list[Trial] = []

    def ride_at(magnitude: float, phase: str) -> bool:
        trial = Trial(magnitude, phase, ride(magnitude))
        trials.append(trial)
        return trial.survived

    low, high = 0.0, None
    magnitude = _rounded(min(search.start, search.cap))
    while high is None:
        if not ride_at(magnitude, "bracket"):
            high = magnitude
        elif magnitude >= search.cap:
            break
        else:
            low, magnitude = magnitude, _rounded(min(2.0 * magnitude, search.cap))
    if high is not None:
        while high - low > search.tolerance:
            middle = _rounded(0.5 * (low + high))
            if not low < middle < high:  # the rounding's floor
                break
            if ride_at(middle, "bisect"):
                low = middle
            else:
                high = middle
    boundary = low
    for _ in range(search.checks):
        ridden = sorted({0.0, boundary, *(t.magnitude for t in trials if t.magnitude < boundary)})
        gaps = [(b - a, a, b) for a, b in zip(ridden, ridden[1:], strict=False)]
        width, a, b = max(gaps, key=lambda gap: gap[0], default=(0.0, 0.0, 0.0))
        if width <= search.tolerance:  # nothing left unexplored below the boundary
            break
        ride_at(_rounded(0.5 * (a + b)), "check")
    falls = [t.magnitude for t in trials if not t.survived]
    lowest_fall = min(falls) if falls else None
    survivors = [t.magnitude for t in trials if t.survived]
    below = [x for x in survivors if lowest_fall is None or x < lowest_fall]
    return Margin(
        margin=max(below, default=0.0),
        boundary=boundary,
        lowest_fall=lowest_fall,
        capped=lowest_fall is None,
        monotone=lowest_fall is None or all(x < lowest_fall for x in survivors),
        trials=tuple(trials),
    )
