"""A board's state from the rider's own feet, as the skateboard paper estimates it.

The feet standing on a board move with it, so the board's platform frame is read off the
stance feet's contact points :math:`c_k` (world, [m]) and velocities:

- origin: their centroid :math:`\\bar c`, less ``footprint`` :math:`o` (in the platform
  frame) when only some of the platform's feet stand on it:
  :math:`p = \\bar c - R_{WP}\\, o`, with :math:`o` the centroid of those feet's points as
  last seen with every foot down, relative to the centroid of all of them. Without it the
  origin moved with the feet: a dog lifting one hind foot moved its deck's estimate
  6 cm forward and 3 cm sideways, and back when the foot came down;
- normal :math:`n`: the least-squares plane through the points (the right singular vector
  of the centred points with the smallest singular value), turned upward. With the
  points on one line (two point feet, one line foot) the tilt about that line is not
  seen by the feet: the normal is then taken perpendicular to the line and as close to
  ``up_hint`` as possible (the world's z by default, or e.g. a line foot's sole normal);
- x axis: for a line foot alone on its platform (``own_platform``, as Cassie's on a
  Hovershoe), along the line of its points when they lie within 45 degrees of the rider's
  forward direction (the sole's toe line turns with the platform it grips), else the
  rider's forward direction, projected on the plane; y = z × x. Read off the rider's
  heading alone, a Hovershoe that turned 0.3 rad under its foot was estimated straight
  ahead (the MPC then never turned it back). Not for one foot of several left in stance on
  a platform (a Segway's, for a moment): its toe line is not the platform's heading, and
  reading it there made the Segway ride fall at 19.6 s instead of 32.7 s;
- yaw, pitch, roll: z-y-x Euler angles of :math:`R_{WP} = [x\\ y\\ z]`; with two feet side
  by side, roll is the slope of the line through them, as in the paper;
- velocity: the mean of the stance feet's world velocities :math:`\\bar{\\dot c}` [m/s];
- yaw rate: from the relative velocity of the feet about the centroid,
  :math:`\\dot\\psi = \\sum_k (r_k \\times \\dot r_k)_z / \\sum_k \\|r_k\\|_{xy}^2` with
  :math:`r_k = c_k - \\bar c` projected on the ground.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.estimation.lapack import svd
from ridempc.estimation.state import BoardEstimate
from ridempc.rotations import rpy_of_matrix

__all__ = ["estimate_board"]

Array = NDArray[np.float64]
COLLINEAR: float = 1e-3  # [m] RMS distance from the best line below which points are a line
FORE_AFT: float = math.cos(math.pi / 4)  # a line this aligned with forward gives the heading
UP: Array = np.array([0.0, 0.0, 1.0])
UP.flags.writeable = False


def _unit_rejection(vector: Array, axis: Array) -> tuple[Array, float]:
    """``vector`` less its component along the unit ``axis``, normalised, and its norm
    before that. The dot products in NumPy (they add up with fused multiply-adds, which
    Python's floats cannot repeat bit for bit), the rest in Python floats: on 3-vectors
    NumPy's calls cost more than their arithmetic, and the floats round the same."""
    along = float(axis @ vector)
    (a, b, c), (u, v, w) = axis.tolist(), vector.tolist()
    return _normalised(np.array((u - a * along, v - b * along, w - c * along)))


def _normalised(vector: Array) -> tuple[Array, float]:
    """``vector`` over its norm, and the norm (np.linalg.norm's sum, without its wrapper)."""
    norm = math.sqrt(vector @ vector)
    if norm == 0.0:  # NumPy's NaN, not Python's ZeroDivisionError
        return vector / norm, norm
    x, y, z = vector.tolist()
    return np.array((x / norm, y / norm, z / norm)), norm


def _normal(centred: Array, up_hint: Array) -> tuple[Array, Array | None]:
    """The plane's upward unit normal, from the points less their centroid [m], and the
    unit direction of their line when they lie on one (else None)."""
    count = len(centred)
    if count == 2:  # two points' line, d/|d| (the SVD's to rounding, without its 5 us)
        difference = centred[1] - centred[0]
        length = math.sqrt(difference @ difference)
        if length > 0.0:
            line = difference / length
            normal, _ = _unit_rejection(up_hint, line)
            return (normal if normal[2] >= 0.0 else -normal), line
    if count >= 2:
        _, singular, vt = svd(centred)
    else:
        singular, vt = np.zeros(1), np.eye(3)
    second = singular[1] if singular.size > 1 else 0.0
    line = None
    if count >= 3 and second / math.sqrt(count) > COLLINEAR:
        normal, _ = _normalised(vt[2])
    elif count >= 2 and singular[0] > 0.0:
        line = vt[0]
        normal, _ = _unit_rejection(up_hint, line)
    else:
        normal, _ = _normalised(up_hint)
    return (normal if normal[2] >= 0.0 else -normal), line


def _yaw_rate(centred: Array, velocities: Array, mean_velocity: Array, spread: float) -> float:
    """:math:`\\dot\\psi = \\sum_k (r_k \\times \\dot r_k)_z / \\sum_k \\|r_k\\|_{xy}^2` [rad/s]
    from the points less their centroid [m], their velocities and mean velocity [m/s] and
    the spread [m^2]. In Python floats: with at most a few points NumPy's calls cost more
    than the sum, which adds up in NumPy's order for fewer than 8 terms (one by one)."""
    mean_x, mean_y = float(mean_velocity[0]), float(mean_velocity[1])
    moment = 0.0
    for (x, y, _), (u, w, _) in zip(centred.tolist(), velocities.tolist(), strict=True):
        moment += x * (w - mean_y) - y * (u - mean_x)
    return moment / spread


def estimate_board(
    feet: tuple[str, ...],
    contact_points: Array,
    velocities: Array,
    forward: Array,
    up_hint: Array | None = None,
    own_platform: bool = False,
    footprint: Array | None = None,
) -> BoardEstimate:
    """The platform state from the points of the feet on it.

    Args:
        feet: Names of the feet the points belong to (recorded in the estimate).
        contact_points: Contact points of those feet [m], world, shape (points, 3).
        velocities: World velocity of each point [m/s], shape (points, 3).
        forward: The rider's forward direction in the world (e.g. the base x axis).
        up_hint: Normal to use about a line of points (default world z).
        own_platform: The points are one foot's, alone on its platform: their line, if
            fore and aft, gives the heading.

    Raises:
        ValueError: No points, or ``forward`` is along the normal.
    """
    points = np.asarray(contact_points, dtype=float).reshape(-1, 3)
    if points.shape[0] == 0:
        raise ValueError("a board estimate needs at least one foot contact point")
    velocities = np.asarray(velocities, dtype=float).reshape(-1, 3)
    hint = UP if up_hint is None else np.asarray(up_hint, dtype=float)
    count = len(points)
    # the centroid and the mean velocity in one column sum (np.mean's own sum and division,
    # not its wrapper): each column adds up in the same order as alone
    means = np.add.reduce(np.concatenate((points, velocities), axis=1)) / count
    centre, mean_velocity = means[:3], means[3:]
    centred = points - centre
    z_axis, line = _normal(centred, hint)
    heading = forward
    if own_platform and line is not None:
        along = line @ forward
        if abs(along) >= FORE_AFT * math.sqrt(forward @ forward):
            heading = line if along > 0.0 else -line
    x_axis, norm = _unit_rejection(heading, z_axis)
    if norm < 1e-6:
        raise ValueError("the rider's forward direction is normal to the board")
    y_axis = np.empty(3)
    mujoco.mju_cross(y_axis, z_axis, x_axis)  # np.cross costs 30 us on 3-vectors, this 1
    rotation = np.array((x_axis, y_axis, z_axis)).T
    roll, pitch, yaw = rpy_of_matrix(rotation)
    origin = centre if footprint is None else centre - rotation @ footprint
    r = centred[:, :2]
    spread = float(np.add.reduce(r * r, axis=None))
    yaw_rate = _yaw_rate(centred, velocities, mean_velocity, spread) if spread > 1e-6 else 0.0
    return BoardEstimate(
        feet=feet,
        position=origin,
        yaw=yaw,
        pitch=pitch,
        roll=roll,
        velocity=mean_velocity,
        yaw_rate=yaw_rate,
    )
