"""The wave pattern chosen by the planner: a low, narrow obstacle passed between the feet.

The Hovershoes paper passes a short obstacle by splitting the feet around it (its wave
pattern); a person decided when. Here the map decides: each group of occupied cells (cells
up to ``join`` apart) is measured along and across its principal axis, and a group no taller than
``max_height`` over the ground and no wider than ``max_width`` across that axis is a
*straddle*. For the planners it stops being an obstacle and becomes a lane: the rider's
centre may come within the inscribed radius of it only inside a band of half-width
``lane`` about its axis, so the path that crosses it runs along the axis, the box between
the shoes (:mod:`ridempc.autonomy.straddle_decision` keeps the decision across replans).
While the rider is in that lane, from ``lead`` before the box to past it, the
command spreads each foot ``spread`` further out (the wave scenario's widest stance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import binary_dilation, distance_transform_edt, label

from ridempc.autonomy.occupancy import GridFrame

__all__ = [
    "Straddle",
    "StraddleSettings",
    "find_straddles",
    "fits",
    "group_cells",
    "lane_walls",
    "measure_groups",
    "onto_axes",
    "straddle_lethal",
]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class StraddleSettings:
    """What the rider can pass between its feet, and how it lines up.

    Attributes:
        max_height: Tallest obstacle straddled, as measured over the ground [m]: the
            straddle course's 0.1 m box measures 0.16 m (depth noise and the ground estimate
            under it); a box that low stays between the decks, below the feet on them and
            the legs rising from them. Taller ones are ridden round.
        max_width: Widest obstacle straddled, as measured across its axis [m]: at the
            wave's widest stance the feet are 0.52 m apart and the shoes' inner sides about
            0.37 m, which leaves a 0.25 m box the lane's 6 cm a side; a measured width runs
            up to a cell of speckle wider each side (the course's 0.2 m box: 0.20-0.30 m).
        lane: Half-width of the lane about the axis the rider's centre keeps to [m].
        lead: Distance before (and after) the obstacle over which the feet are spread [m]:
            the spread's slew needs 0.5 s, 0.25 m at 0.5 m/s; the MPC rider's spread moves
            mostly its left platform (its library frame follows that one) and the rider
            drifts 5-7 cm with it, which the band corrects over about the look-ahead.
        spread: Each foot's lateral offset while straddling [m] (the wave scenario's 0.05).
        spread_rate: Slew of that offset [m/s] (the wave's 0.08 m/s peak, at 0.05 m / 4 s).
        min_cells: Fewest cells of a straddle: a smaller group is more likely speckle
            than a box (a 0.1 m box fills four), and stays an obstacle to ride round, not a
            lane that would draw the path onto its axis.
        look_ahead: The local goal's distance along the path while straddling [m]: the
            rider closes a lateral error over about this distance, and 1.75 m (the
            paper's) let the MPC rider drift 7 cm off the axis over the 0.6 m box.
        join: Cells up to this far apart are one group [m]: a box's top and faces are
            seen a cell apart where the depth noise leaves a cell unhit (a lone cell
            inside the straddle course's box, taken for an obstacle of its own, sent the
            path round it); two 5 cm cells, narrower than any gap a rider passes.
        decide_range: A group is decided (straddle or obstacle) once the rider is this
            close to it [m]: the depth's sigma, 0.004 z^2, is 0.025 m here (0.036 m at
            the 3 m fusing range), a quarter of the margin between a 0.1 m box's measured
            top and ``max_height``; beyond it a low group is taken as a straddle, a
            speck of fewer than ``min_cells`` neither straddled nor ridden round.
        height_margin: A decided straddle stays one until measured this much taller
            than ``max_height`` [m] (hysteresis: twice the depth's sigma at the
            deciding range, so a top that noise lifts as frames fuse does not flip it).
        width_margin: ... and this much wider than ``max_width`` [m] (a cell of speckle
            at each side).
    """

    max_height: float = 0.2
    max_width: float = 0.35
    lane: float = 0.06
    lead: float = 1.2
    spread: float = 0.05
    spread_rate: float = 0.1
    look_ahead: float = 0.8
    min_cells: int = 4
    join: float = 0.1
    decide_range: float = 2.5
    height_margin: float = 0.05
    width_margin: float = 0.1


@dataclass(frozen=True)
class Straddle:
    """A low, narrow obstacle to pass between the feet.

    Attributes:
        cells: Its occupied cells, a mask of the grid's shape.
        center: Centre of its cells (x, y) [m].
        axis: Unit vector of its long axis (x, y), the direction it is ridden along.
        half_length: Half its extent along the axis, to the cells' outer edges [m].
        half_width: Half its extent across the axis, to the cells' outer edges [m].
        height: Its tallest point over the ground [m].
    """

    cells: NDArray[np.bool_]
    center: Array
    axis: Array
    half_length: float
    half_width: float
    height: float

    def local(self, xy: Array) -> tuple[Array, Array]:
        """Coordinates of world points (x, y) [m], shape (n, 2), along and across the axis."""
        d = np.atleast_2d(xy) - self.center
        normal = np.array([-self.axis[1], self.axis[0]])
        return d @ self.axis, d @ normal

    def in_lane(self, xy: Array, lane: float, lead: float) -> bool:
        """Whether the point (x, y) [m] is within ``lane`` of the axis and within ``lead``
        of the obstacle's ends along it."""
        along, across = self.local(np.asarray(xy, dtype=float).reshape(1, 2))
        return bool(abs(across[0]) <= lane and abs(along[0]) <= self.half_length + lead)


def find_straddles(
    frame: GridFrame,
    occupied: NDArray[np.bool_],
    height: Array,
    settings: StraddleSettings,
    rider: Array,
) -> tuple[Straddle, ...]:
    """The groups of occupied cells low and narrow enough to straddle, decided afresh from
    this one map (no memory: :class:`~ridempc.autonomy.straddle_decision.StraddleTracker`
    keeps one across replans).

    Args:
        frame: The grid's geometry.
        occupied: Occupied cells.
        height: Tallest obstacle point seen in each cell, over the ground [m] (an occupied
            cell without one, -inf, is not known to be low).
        settings: What can be straddled.
        rider: The rider's position (x, y) [m].
    """
    return tuple(
        group
        for group in measure_groups(
            frame, occupied, height, settings, rider, settings.max_height, settings.max_width
        )
        if fits(group, settings.max_height, settings.max_width, settings.min_cells)
    )


def fits(group: Straddle, max_height: float, max_width: float, min_cells: int) -> bool:
    """Whether a measured group is at most ``max_height`` tall and ``max_width`` wide [m]
    and holds at least ``min_cells`` cells."""
    return (
        group.height <= max_height
        and 2.0 * group.half_width <= max_width
        and int(group.cells.sum()) >= min_cells
    )


def group_cells(occupied: NDArray[np.bool_], join: int) -> tuple[NDArray[np.int32], int]:
    """Labels of the groups of occupied cells: cells up to ``join`` free cells apart are
    one group (a box's faces seen with a gap are one box), and the group's count."""
    reach = np.ones((2 * join + 1, 2 * join + 1), dtype=bool)
    joined = binary_dilation(occupied, structure=reach) if join > 0 else occupied
    labels, count = label(joined, structure=np.ones((3, 3), dtype=bool))
    labels[~occupied] = 0
    return labels, int(count)


def measure_groups(
    frame: GridFrame,
    occupied: NDArray[np.bool_],
    height: Array,
    settings: StraddleSettings,
    rider: Array,
    tallest: float,
    widest: float,
) -> tuple[Straddle, ...]:
    """The groups of occupied cells (:func:`group_cells`, ``settings.join`` apart) no taller
    than ``tallest`` [m], each measured along and across its principal axes.

    Of the axes across which a group is at most ``widest`` [m] wide, the one pointing most
    nearly from the rider to it is the axis it would be ridden along (a box seen only by
    its front face is narrow both ways); across neither: the narrower.
    """
    labels, count = group_cells(occupied, round(settings.join / frame.resolution))
    if count == 0:
        return ()
    measured = np.where(np.isfinite(height), height, np.inf)  # none seen: not known low
    top = np.zeros(count + 1)
    np.maximum.at(top, labels[occupied], measured[occupied])
    found = []
    r = frame.resolution
    for k in np.nonzero(top[1:] <= tallest)[0] + 1:
        i, j = np.nonzero(labels == k)
        if len(i) == 0:
            continue
        xy = np.column_stack([frame.origin[0] + (i + 0.5) * r, frame.origin[1] + (j + 0.5) * r])
        center = xy.mean(axis=0)
        if len(xy) > 1:
            _, vectors = np.linalg.eigh(np.cov((xy - center).T))
        else:
            vectors = np.eye(2)
        approach = center - np.asarray(rider, dtype=float)
        best: tuple[tuple[bool, float], Array, float, float] | None = None
        for axis in (vectors[:, 1], vectors[:, 0]):
            normal = np.array([-axis[1], axis[0]])
            along, across = (xy - center) @ axis, (xy - center) @ normal
            # a cell's own extent along either direction
            pad = 0.5 * r * (abs(axis[0]) + abs(axis[1]))
            # extents between the 5th and 95th percentiles: a stray cell at a side (one
            # made a box 0.35 m wide for a moment, and the path went round) does not count
            half_width = 0.5 * float(np.subtract(*np.percentile(across, [95, 5]))) + pad
            half_length = 0.5 * float(np.subtract(*np.percentile(along, [95, 5]))) + pad
            # narrow enough first, then the most aligned with the approach (else the narrower)
            narrow = 2.0 * half_width <= widest
            rank = (narrow, abs(float(axis @ approach)) if narrow else -half_width)
            if best is None or rank > best[0]:
                best = (rank, axis, half_length, half_width)
        assert best is not None
        _, axis, half_length, half_width = best
        found.append(
            Straddle(
                cells=labels == k,
                center=center,
                axis=axis,
                half_length=half_length,
                half_width=half_width,
                height=float(top[k]),
            )
        )
    return tuple(found)


def straddle_lethal(
    frame: GridFrame, straddles: tuple[Straddle, ...], inscribed: float, lane: float
) -> NDArray[np.bool_]:
    """Cells where the rider's centre may not be because of the straddles: within
    ``inscribed`` [m] of one, outside its lane of half-width ``lane`` [m]."""
    lethal = np.zeros(frame.shape, dtype=bool)
    if not straddles:
        return lethal
    x, y = frame.centers()
    xy = np.column_stack([x.reshape(-1), y.reshape(-1)])
    for straddle in straddles:
        near = distance_transform_edt(~straddle.cells) * frame.resolution <= inscribed
        _, across = straddle.local(xy)
        lethal |= near & (np.abs(across) > lane).reshape(frame.shape)
    return lethal


def onto_axes(path: Array, straddles: tuple[Straddle, ...], reach: float, lane: float) -> Array:
    """The path (x, y) [m], shape (n, 2), with its points within ``lane`` [m] of a
    straddle's axis and within ``reach`` [m] of its ends moved onto the axis: the global
    plan's coarse cells leave it a cell off the line the rider must keep to."""
    out = np.array(path, dtype=float)
    for straddle in straddles:
        along, across = straddle.local(out)
        inside = (np.abs(across) <= lane) & (np.abs(along) <= straddle.half_length + reach)
        out[inside] = straddle.center + along[inside, None] * straddle.axis
    return out


def lane_walls(straddle: Straddle, clearance: float, lane: float, spacing: float = 0.15) -> Array:
    """Points (x, y) [m] for the local planner, in two lines parallel to the axis at
    ``clearance + lane`` [m] from it, along the obstacle and ``clearance`` beyond its ends:
    a band that keeps ``clearance`` from them stays within ``lane`` of the axis."""
    reach = straddle.half_length + clearance
    along = np.linspace(-reach, reach, max(2, math.ceil(2.0 * reach / spacing) + 1))
    normal = np.array([-straddle.axis[1], straddle.axis[0]])
    offset = clearance + lane
    points = [
        straddle.center + a * straddle.axis + side * offset * normal
        for side in (-1.0, 1.0)
        for a in along
    ]
    return np.asarray(points)
