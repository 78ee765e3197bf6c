"""The backup's reach after a falling platform, told by the rider's drop watch.

A backup law with a flight phase of its own (the Hovershoes PD's: a leg whose foot is
unloaded reaches down after its platform, :mod:`ridempc.baselines.hovershoe_flight`) reads
a platform in the air from the legs' loads alone. Riding alone that is its design; beside
the MPC it is wrong more often: a push the MPC leans against before it hands the ride over
(:mod:`ridempc.mpc.impulse`) tips the rider onto one platform and holds the other foot
unloaded, and the backup, standing by and then riding, lengthens that leg after a platform
that never fell. The rider already tells a drop from a push (:mod:`ridempc.mpc.drop`: every
foot unloaded while the rider is not rising, or every foot sinking); lent that watch, the
backup reaches only once it has told a drop, and a push leaves its legs at their length.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

from ridempc.controllers.base import Controller
from ridempc.mpc.stages.triggers import DropWatch

__all__ = ["ReachesAfterPlatforms", "lend_drop_watch"]


@runtime_checkable
class ReachesAfterPlatforms(Protocol):
    """A law whose legs reach down after a falling platform, told by a witness when one is
    lent (None: by its own reading of the legs' loads)."""

    shoes_falling: Callable[[], bool] | None


def lend_drop_watch(backup: Controller, watch: DropWatch | None) -> bool:
    """Lend ``watch`` (updated each tick before the backup runs) to ``backup`` as its
    witness of the platforms falling; returns whether it took it (a backup with a flight
    phase, and a pair with the ``drop`` stage)."""
    if watch is None or not isinstance(backup, ReachesAfterPlatforms):
        return False
    backup.shoes_falling = lambda: watch.dropping
    return True
