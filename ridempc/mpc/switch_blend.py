"""Blending a newly switched reference in from the rider's state at the switch.

A library entry starts from its own first knot: the keyframe on a board at rest, or, for a
``repush`` (pushing the skateboard again from a rolling deck), the keyframe on a deck rolling
at the entry's start speed. A rider switched onto it mid-ride stands wherever the ride left
her on the deck: 3 cm further forward than the ``repush`` entries' first knot after a coast.
Tracked from its first tick, the reference then asks for that offset back at once, and the
skateboard's rider can only move her body along the deck by pushing the deck the other way
(8.9 kg of dog against 3.2 kg of deck): the MPC's first plans braked the deck from 0.49 to
0.30 m/s before the first push, which then met a board slower than it was planned for.

:class:`SwitchBlend` lays the offset between the rider's state and the reference at the
switch over the reference's rows and lets it fade out before the entry's first push:

.. math::

    x^{ref}_k \\leftarrow x^{ref}_k + (1 - w(t_k))\\,\\delta, \\qquad
    w(t) = \\tfrac12 \\left(1 - \\cos \\frac{\\pi \\min(t, T)}{T}\\right)

with :math:`\\delta = \\hat x_0 - x^{ref}(t_0)` in the rider's pose (the centre of mass
relative to the first platform, the trunk's roll and pitch, the joints), :math:`T` the time
of the entry's first push (a ground contact) and the centre of mass's velocity rows given
:math:`-\\dot w(t_k)\\,\\delta` so the blend is a motion the model can follow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["SwitchBlend", "first_push_time"]

Array = NDArray[np.float64]
# [s] the shortest blend: a reference whose first push comes at once still fades over a few
# MPC steps rather than jumping
MIN_BLEND: float = 0.1
# the centre of mass's place rows and the velocity rows that carry their blend's rate
_PLACES: tuple[tuple[str, str], ...] = (("com_x", "vx"), ("com_y", "vy"), ("com_z", "vz"))


def first_push_time(reference: MotionReference) -> float:
    """Time of the reference's first phase with a foot on the ground [s] (its duration
    when it has none)."""
    elapsed = 0.0
    for phase in reference.phases:
        if Contact.GROUND in phase.contacts:
            return elapsed
        elapsed += phase.duration
    return elapsed


@dataclass(frozen=True)
class SwitchBlend:
    """The offset between the rider and a newly switched reference, fading out.

    Attributes:
        start: Reference time of the switch [s].
        duration: Time over which the offset fades, :math:`T` minus ``start`` [s].
        offsets: :math:`\\delta` (nx), zero outside the rider's pose.
        rates: Per blended place row, its velocity row (or -1: none).
    """

    start: float
    duration: float
    offsets: Array
    rates: tuple[tuple[int, int], ...]

    @classmethod
    def at_switch(
        cls,
        problem: MpcProblem,
        reference: MotionReference,
        layout: StateLayout,
        t_ref: float,
    ) -> SwitchBlend:
        """The blend from the rider's state (``problem``'s initial state, nx) to its state
        reference (as shaped by the commands: a commanded deck roll replaces the entry's)
        at reference time ``t_ref`` [s] of ``reference``."""
        names = layout.names
        x0, here = problem.initial_state, problem.state_reference[0]
        platform = layout.prefixes[0]
        offsets = np.zeros(len(x0))
        rates = []
        for place, rate in _PLACES:
            i = names[place]
            offsets[i] = x0[i] - here[i]
            axis = place[-1]
            if f"{platform}{axis}" in names:  # along the deck: relative to the platform
                j = names[f"{platform}{axis}"]
                offsets[i] -= x0[j] - here[j]
            rates.append((i, names.get(rate, -1)))
        base = layout.base_prefix
        angles = (f"{base}roll", f"{base}pitch", f"{platform}roll", f"{platform}roll_rate")
        for name, i in names.items():
            if name.startswith("q_") or name in angles:
                offsets[i] = x0[i] - here[i]
        duration = max(first_push_time(reference) - t_ref, MIN_BLEND)
        return cls(t_ref, duration, offsets, tuple(rates))

    def weights(self, times: Array) -> tuple[Array, Array]:
        """:math:`1 - w` and :math:`-\\dot w` [1/s] at reference ``times`` [s]."""
        phase = np.clip((times - self.start) / self.duration, 0.0, 1.0)
        remaining = 0.5 * (1.0 + np.cos(math.pi * phase))
        rate = -0.5 * math.pi / self.duration * np.sin(math.pi * phase)
        return remaining, rate

    def done(self, t_ref: float) -> bool:
        return t_ref >= self.start + self.duration

    def __call__(self, problem: MpcProblem, t_ref: float) -> MpcProblem:
        """The problem at reference time ``t_ref`` [s] with the offset laid over its
        state reference."""
        states = problem.state_reference.copy()
        times = np.asarray(t_ref + problem.dt * np.arange(len(states)), dtype=float)
        remaining, rate = self.weights(times)
        states += remaining[:, None] * self.offsets[None, :]
        for place, velocity in self.rates:
            if velocity >= 0:
                states[:, velocity] += rate * self.offsets[place]
        return replace(problem, state_reference=states)
