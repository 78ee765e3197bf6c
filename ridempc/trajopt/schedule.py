"""Contact schedules: which foot is on the board, on the ground or in the air, and when.

The skateboard paper's contact scheduler (Sec. IV-A) is periodic: acceleration trajectories
share a push period of 1.2 s and differ in their number of strides; only the pushing leg
changes phase, the other legs stay on the deck. A trajectory passes through the paper's three
modes (Sec. III): four-leg balancing (every foot on the deck), three-leg balancing (the
pushing leg swinging between deck and ground) and acceleration (the pushing leg on the
ground). One schedule is plain data: a tuple of :class:`Phase`, each a duration and a
:class:`Contact` per foot, on a uniform grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

from ridempc.errors import ConfigError

__all__ = [
    "Contact",
    "ContactSchedule",
    "Phase",
    "push_schedule",
    "strides_for",
]


class Contact(StrEnum):
    """Where one foot is during a phase."""

    BOARD = "board"  # on the deck, moving with it (eq. 15)
    GROUND = "ground"  # on the ground, still in the world (the push)
    SWING = "swing"  # in the air, no force


@dataclass(frozen=True)
class Phase:
    """One phase of a schedule.

    Attributes:
        mode: The paper's mode name (``four-leg``, ``three-leg``, ``push``, ...).
        duration: Length [s], a whole number of grid intervals.
        contacts: Per foot, where it is.
        swing_from: For a swinging foot, the surface it leaves (``BOARD`` or ``GROUND``).
        swing_to: For a swinging foot, the surface it lands on.
    """

    mode: str
    duration: float
    contacts: tuple[Contact, ...]
    swing_from: Contact | None = None
    swing_to: Contact | None = None


@dataclass(frozen=True)
class ContactSchedule:
    """Phases on a uniform grid of step ``dt`` [s]."""

    phases: tuple[Phase, ...]
    dt: float

    def __post_init__(self) -> None:
        if not self.phases:
            raise ConfigError("a contact schedule needs at least one phase")
        sizes = {len(p.contacts) for p in self.phases}
        if len(sizes) != 1:
            raise ConfigError("every phase of a contact schedule must name every foot")
        for p in self.phases:
            steps = p.duration / self.dt
            if abs(steps - round(steps)) > 1e-9 or round(steps) < 1:
                raise ConfigError(
                    f"phase '{p.mode}' lasts {p.duration} s, not a whole number of "
                    f"{self.dt} s intervals"
                )

    @property
    def n_feet(self) -> int:
        return len(self.phases[0].contacts)

    @property
    def intervals_per_phase(self) -> tuple[int, ...]:
        return tuple(round(p.duration / self.dt) for p in self.phases)

    @property
    def n_intervals(self) -> int:
        return sum(self.intervals_per_phase)

    @property
    def duration(self) -> float:
        """Total duration [s]."""
        return self.n_intervals * self.dt

    @property
    def times(self) -> NDArray[np.float64]:
        """Node times [s], ``n_intervals + 1`` of them."""
        return np.arange(self.n_intervals + 1, dtype=np.float64) * self.dt

    def phase_of_interval(self) -> NDArray[np.int64]:
        """Index of the phase each interval belongs to (``n_intervals``,)."""
        return np.repeat(np.arange(len(self.phases)), self.intervals_per_phase)

    def contact_masks(self) -> dict[Contact, NDArray[np.float64]]:
        """Per contact kind, a 0/1 array (``n_intervals`` x ``n_feet``)."""
        phase = self.phase_of_interval()
        return {
            kind: np.array(
                [[1.0 if c is kind else 0.0 for c in self.phases[i].contacts] for i in phase]
            )
            for kind in Contact
        }

    def mode_codes(self) -> NDArray[np.int64]:
        """Per interval, the index of its phase's mode in :meth:`mode_names`."""
        names = self.mode_names()
        return np.array([names.index(self.phases[i].mode) for i in self.phase_of_interval()])

    def mode_names(self) -> list[str]:
        names: list[str] = []
        for p in self.phases:
            if p.mode not in names:
                names.append(p.mode)
        return names


def strides_for(target: float, speed_per_stride: float = 0.3) -> int:
    """Number of pushes to reach ``target`` [m/s]: one per ``speed_per_stride`` [m/s]."""
    return max(1, math.ceil(target / speed_per_stride - 1e-9))


def push_schedule(
    target: float,
    n_feet: int,
    pusher: int,
    dt: float = 0.05,
    period: float = 1.2,
    sweep: float = 0.2,
    settle: float = 0.3,
    speed_per_stride: float = 0.3,
    min_push: float = 0.2,
    max_push: float = 0.5,
    start_speed: float = 0.0,
) -> ContactSchedule:
    """The acceleration schedule of the skateboard paper for one target speed.

    Four-leg balancing for ``settle``, then ``strides`` pushes of period ``period``, each a
    swing of the pushing leg followed by its push on the ground (the first swing, from the
    deck to the ground, is three-leg balancing; the later ones, ground to ground, the
    acceleration mode's recovery), then a swing back onto the deck (three-leg) and four-leg
    balancing for ``settle``. The pushing foot stays
    still on the ground while the board passes, so a push is no longer than the foot can
    sweep (``sweep`` [m]) at the speed the board is expected to have then (a linear ramp),
    within ``[min_push, max_push]``; each period keeps its 1.2 s.

    Args:
        target: Final board speed [m/s].
        n_feet: Number of feet.
        pusher: Index of the pushing foot.
        dt: Grid step [s].
        period: Push period [s] (1.2 s in the paper).
        sweep: Distance the pushing foot can travel relative to the trunk [m].
        settle: Four-leg balancing at the start and at the end [s].
        speed_per_stride: Speed gained per push, which sets the number of strides [m/s].
        min_push: Shortest push [s].
        max_push: Longest push [s].
        start_speed: Board speed at the start [m/s]: a rolling board pushed again needs
            the strides of the speed it gains, and one more for what the wheels' rolling
            resistance takes while it pushes (0.16 m/s^2 over a stride's 2.3 s: more than
            one push adds).
    """
    strides = strides_for(target - start_speed, speed_per_stride) + (start_speed > 0.0)

    def snap(t: float) -> float:
        return round(t / dt) * dt

    def contacts(kind: Contact) -> tuple[Contact, ...]:
        return tuple(kind if i == pusher else Contact.BOARD for i in range(n_feet))

    phases = [Phase("four-leg", snap(settle), contacts(Contact.BOARD))]
    for s in range(strides):
        expected = start_speed + (target - start_speed) * (s + 0.5) / strides
        push = snap(min(max_push, max(min_push, sweep / max(expected, 1e-6))))
        start, mode = (Contact.BOARD, "three-leg") if s == 0 else (Contact.GROUND, "recover")
        phases.append(
            Phase(mode, snap(period - push), contacts(Contact.SWING), start, Contact.GROUND)
        )
        phases.append(Phase("push", push, contacts(Contact.GROUND)))
    phases.append(
        Phase("three-leg", snap(period / 2), contacts(Contact.SWING), Contact.GROUND, Contact.BOARD)
    )
    phases.append(Phase("four-leg", snap(settle), contacts(Contact.BOARD)))
    return ContactSchedule(tuple(phases), dt)
