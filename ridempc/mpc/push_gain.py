"""A re-push's speeds laid from the board's own: the push adds what it planned to add.

A ``repush`` entry plans its pushes from the rolling start it was solved for (the board at
its target less :data:`~ridempc.mpc.manoeuvre.REPUSH_BAND`). The board the rider meets at
the first push is slower than that (the switch and rolling resistance take 0.1-0.2 m/s off
it, more on a rolled deck), and a reference that asks the centre of mass for the planned
speed at once has the pushing leg drive the body forward faster than the deck under it:
the deck feet then drag the 3.2 kg deck along (a board at 0.29 m/s kicked to 1.03 m/s
within 0.2 s, and the rider fell). Scaled down instead as a coast is
(:meth:`~ridempc.mpc.manoeuvre.ManoeuvreSelector.coasting`), the push shrinks with the
speed lost, and a slow board is pushed ever more weakly until it stops.

So from the first push on the reference's speeds are *shifted*: with :math:`\\Delta v = v -
v^{ref}_0` the board's speed :math:`v` [m/s] less the reference's at node 0, every node's
forward speed (the centre of mass's along the board's heading and each platform's) gains
:math:`\\Delta v`, and the horizontal places the same speed integrated,
:math:`p_k \\mathrel{+}= \\Delta v \\sum_{j<k} (\\cos\\psi_j, \\sin\\psi_j)\\, \\Delta t`
(:math:`\\psi` the first platform's heading): the push gains over the horizon what the
entry gains there, from wherever the board is.

Shifted so at every tick alone, a stroke that falls short is never asked back: the next
starts from the slower board. So the reference is *anchored* at the re-push's first push
(:class:`PushAnchor`): there the board's offset from the entry, :math:`\\Delta = v(t_a) -
v^{ref}(t_a)`, is taken once, and the re-push is to ride

.. math:: r(t) = v^{ref}(t) + \\Delta + u\\, g(t) / G,

the entry's gain from the board it met plus the outer loop's :math:`u`
(:mod:`~ridempc.mpc.push_speed`), added as the pushing foot adds momentum: :math:`g(t)` is
the entry's ground time from :math:`t_a` to :math:`t`, :math:`G` all of it. Node 0 is still
the board (a reference ahead of the board at node 0 had the deck feet drive the deck
against the body: a board at 0.31 m/s braked to 0.15 in 0.2 s while the body ran ahead);
the board's deficit behind :math:`r` there, :math:`D = r(t_0) - v`, at most
:math:`u_{max}`, is asked back over the ground time left, :math:`f_k = (g(t_k) - g(t_0)) /
(G - g(t_0))`, so every node's speed changes by

.. math:: \\delta_k = v - v^{ref}(t_0) + \\mathrm{clip}(D, 0, u_{max})\\, f_k
    + u\\, (g(t_k) - g(t_0)) / G,

which with no deficit and no :math:`u` is the plain shift above. What the anchor adds never
takes a node's board speed past the held speed and the loop's gain, :math:`v^* + u`
(above the plain shift it is cut there, below it is not asked): an entry overshoots its
target in its last stroke (the body to 0.88 m/s for 0.7, handing the board its momentum
after), laid for a board that met its plan; asked back on top of that, a stroke on a board
held at 0.5-0.7 m/s drove the pair to 0.83 m/s and the ride into a fall.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.push_speed import GAIN_LIMIT
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.schedule import Contact

__all__ = ["PushAnchor", "ground_time", "shifted_speeds"]

Array = NDArray[np.float64]


def ground_time(reference: MotionReference, times: Array) -> Array:
    """The entry's time with a foot on the ground from its start to each of ``times`` [s]
    (reference time): the time in which the pushing foot adds momentum."""
    times = np.asarray(times, dtype=float)
    total, start = np.zeros_like(times), 0.0
    for phase in reference.phases:
        end = start + phase.duration
        if Contact.GROUND in phase.contacts:
            total += np.clip(times, start, end) - start
        start = end
    return total


class PushAnchor:
    """A re-push's speeds anchored at its first push (see the module docstring).

    Args:
        limit: The most of the board's deficit asked back, :math:`u_{max}` [m/s].
    """

    def __init__(self, limit: float = GAIN_LIMIT) -> None:
        self.limit = limit
        self._anchor: tuple[float, float] | None = None  # (t_a, Delta) [s], [m/s]

    def reset(self) -> None:
        """Forget the anchor (a manoeuvre began)."""
        self._anchor = None

    def extra(
        self,
        reference: MotionReference,
        times: Array,
        entry_speeds: Array,
        speed: float,
        gain: float,
        held: float,
    ) -> Array:
        """:math:`\\delta_k - (v - v^{ref}(t_0))` [m/s], what the anchor adds to the plain
        shift at the nodes' reference ``times`` [s], with ``entry_speeds`` the entry's board
        speed at the nodes [m/s], ``speed`` the board's [m/s], ``gain`` the loop's :math:`u`
        [m/s] and ``held`` the held speed :math:`v^*` [m/s]; anchored at the first call
        since :meth:`reset`."""
        entry_speeds = np.asarray(entry_speeds, dtype=float)
        entry_speed = float(entry_speeds[0])
        if self._anchor is None:
            self._anchor = (float(times[0]), speed - entry_speed)
        start, offset = self._anchor
        ground = ground_time(reference, np.concatenate([[start], times, [reference.duration]]))
        nodes, whole = ground[1:-1] - ground[0], ground[-1] - ground[0]
        gained = gain * nodes / whole if whole > 0.0 else np.zeros_like(nodes)
        deficit = entry_speed + offset + gained[0] - speed
        left = whole - nodes[0]
        share = (nodes - nodes[0]) / left if left > 0.0 else np.zeros_like(nodes)
        extra = min(max(deficit, 0.0), self.limit) * share + gained - gained[0]
        plain = entry_speeds + speed - entry_speed
        return np.minimum(extra, np.maximum(held + gain - plain, 0.0))


def shifted_speeds(
    problem: MpcProblem, layout: StateLayout, speed: float, extra: Array | None = None
) -> MpcProblem:
    """``problem`` with its reference's speeds shifted to start at the board's ``speed``
    [m/s] (see the module docstring), each node's by ``extra`` [m/s] (nodes,) more."""
    names = layout.names
    platform = layout.prefixes[0]
    states = problem.state_reference.copy()
    board_speed = layout.speed(platform)
    heading = layout.heading(platform)
    if board_speed is None or heading is None:
        return problem
    change = float(speed) - float(states[0, board_speed]) + np.zeros(len(states))
    if extra is not None:
        change += extra
    direction = np.column_stack([np.cos(states[:, heading]), np.sin(states[:, heading])])
    steps = change[:-1, None] * direction[:-1] * problem.dt
    travelled = np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])
    for prefix in ("com_", *layout.prefixes):
        states[:, [names[f"{prefix}x"], names[f"{prefix}y"]]] += travelled
    states[:, [names["vx"], names["vy"]]] += change[:, None] * direction
    for prefix in layout.prefixes:
        index = layout.speed(prefix)
        if index is not None:
            states[:, index] += change
    return replace(problem, state_reference=states)
