"""No posture fade for a handover in the first divergence time of a ride the MPC starts.

At a handover the offset between the joints and the backup's position targets is laid
over those targets and fades out over :data:`~ridempc.mpc.handover.POSTURE_FADE_S`
(:class:`~ridempc.mpc.handover.PostureFade`), so that a posture the primary *chose* (a
deeper crouch, a pelvis twisted over the feet) is not pulled back at once. A chosen posture
takes the primary's plan longer than the rider's divergence time to build:

.. math:: T_{start} = 1 / \\omega = \\sqrt{h / g}

(0.28 s for Cassie's centre of mass 0.8 m over her feet), since the plan brings a crouch in
over seconds and a lean grows no faster than :math:`e^{\\omega t}`. A handover before
:math:`T_{start}` of a ride that *started* on the primary finds no such posture, only the
first ticks' tracking error of a model that does not fit the rider yet (a payload, a moved
centre of mass): on the Segway one knee bent 0.14-0.18 rad off the backup's targets within
0.064 s where the backup alone keeps it within 0.04 rad. Laid over the backup's targets,
that error is held for half a second, and the backup, which stands the ride from its own
start, rides on from a buckled leg. So such a handover takes no fade: the backup's targets
at once, as in its own ride.

Only the ride's first handover, and only where the primary took the ride at the start
(not after a start on the backup, :meth:`~ridempc.mpc.handover.Handover.start_on_backup`,
where the primary's posture at its takeover is the backup's own).
"""

from __future__ import annotations

import math

from ridempc.mpc.divergence import GRAVITY
from ridempc.mpc.handover import Handover

__all__ = ["StartFade", "start_window"]


def start_window(com_height: float) -> float:
    """:math:`T_{start} = \\sqrt{h/g}` [s], the rider's divergence time, with the centre of
    mass ``com_height`` [m] over the feet (at least a decimetre: a height not yet measured
    is no reason for a window of zero)."""
    return math.sqrt(max(com_height, 0.1) / GRAVITY)


class StartFade:
    """Sets the handover's posture fade each tick: none within :func:`start_window` of a
    ride started on the primary, before its first handover; the configured one otherwise.

    Args:
        handover: The rider's handover; its ``fade_s`` at construction is the configured
            fade [s].
    """

    def __init__(self, handover: Handover) -> None:
        self.handover = handover
        self.fade_s = handover.fade_s
        self._start: float | None = None  # [s] the ride's first tick

    def __call__(self, now: float, com_height: float) -> float:
        """The fade [s] for a handover at ``now`` [s] with the centre of mass
        ``com_height`` [m] over the feet, set on the handover."""
        self._start = now if self._start is None else self._start
        handover = self.handover
        on_primary_from_start = handover.takeover_s is None and not handover.starting
        early = now - self._start < start_window(com_height)
        first = not handover.fallbacks
        handover.fade_s = 0.0 if on_primary_from_start and early and first else self.fade_s
        return handover.fade_s
