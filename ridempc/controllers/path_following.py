"""Following a commanded path: a cross-track-to-yaw-rate law around any rider that turns.

The rider reads its own pose (the visual-inertial odometry's position, heading and
velocity, carried over its latency at its velocity), in the path frame laid at its pose
when it starts following (:class:`~ridempc.scenarios.path.PathFrame`), and, with
:math:`e` its cross-track error (positive left of the path), :math:`\\theta = \\psi -
\\psi_p` its heading against the path's, :math:`\\kappa_p` the path's curvature read
``preview`` [s] ahead (the lag of a board that turns through a roll) and :math:`v` its
forward speed, asks for the yaw rate

.. math:: \\omega^* = v \\left(\\kappa_p - \\frac{e}{D^2} - \\frac{2 \\sin\\theta}{D}\\right)

which, along the path, makes :math:`e'' + (2/D) e' + e / D^2 = 0` in arc length: the error
dies out critically damped over a distance :math:`D` [m], at any speed. The yaw rate is
bounded by what the board can steer at that speed (``max_yaw_rate``, e.g. the skateboard's
:meth:`~ridempc.boards.skateboard.steering.RollSteering.max_yaw_rate`).

:class:`PathFollowing` wraps a rider controller: from the path's ``start`` on, it replaces
the command's yaw rate by the law's, for the rider and for its preview of the command
timeline (over which the yaw rate is held at the law's latest); before it, the scenario's
commands pass through unchanged. Written for any board the rider can steer.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ridempc.boards.board import Board
from ridempc.boards.steering import steering_limits
from ridempc.controllers.base import Controller
from ridempc.scenarios.path import CirclePath, PathFrame, PathGeometry, SlalomPath
from ridempc.scenarios.scenario import Command
from ridempc.sim.motors import MotorCommand
from ridempc.sim.sensors import SensorPacket

__all__ = ["DISTANCE", "PREVIEW", "PathFollowing", "follow_path", "path_yaw_rate"]

# [m] the cross-track error's settling distance: about two wheelbases of the skateboard's
# steering lag (0.3 s at 0.7 m/s is 0.2 m), so the loop stays well inside the roll's bandwidth.
DISTANCE: float = 1.5
# [s] how far ahead the path's curvature is read: the skateboard's deck roll takes about
# this long to reach a new reference.
PREVIEW: float = 0.3


def path_yaw_rate(
    cross_track: float, heading_error: float, curvature: float, speed: float, distance: float
) -> float:
    """The law's yaw rate [rad/s] (see the module docstring).

    Args:
        cross_track: :math:`e`, positive left of the path [m].
        heading_error: :math:`\\theta = \\psi - \\psi_p` [rad].
        curvature: :math:`\\kappa_p`, positive turning left [1/m].
        speed: :math:`v`, forward [m/s].
        distance: :math:`D` [m].
    """
    return speed * (
        curvature - cross_track / distance**2 - 2.0 * math.sin(heading_error) / distance
    )


class PathFollowing(Controller):
    """A rider controller that follows a path by its yaw-rate command.

    Args:
        inner: The rider controller, built for its robot and board.
        path: The commanded path.
        max_yaw_rate: The largest yaw rate [rad/s] the board steers at a speed [m/s], or
            None for no bound.
        distance: :math:`D` [m].
        preview: How far ahead the curvature is read [s].
    """

    def __init__(
        self,
        inner: Controller,
        path: CirclePath | SlalomPath,
        max_yaw_rate: Callable[[float], float] | None = None,
        distance: float = DISTANCE,
        preview: float = PREVIEW,
    ) -> None:
        self.inner = inner  # before the base sets the preview, which hands it on
        super().__init__(inner.robot, inner.board)
        self.rate_hz = inner.rate_hz
        self.uses_ground_truth = inner.uses_ground_truth
        self.path = path
        self.geometry = PathGeometry(path)
        self.max_yaw_rate = max_yaw_rate
        self.distance = distance
        self.preview = preview
        self._index: int | None = None
        self._frame: PathFrame | None = None  # the rider's pose at the path's start
        self._yaw_rate = 0.0
        self._timeline: Callable[[float], Command] | None = None
        # when the law last ran [s], the arc it read the curvature at [m], the rider's speed
        # [m/s] and that curvature [1/m]: the turn ahead (turn_ahead)
        self._ahead: tuple[float, float, float, float] | None = None
        inner.turn_preview = self.turn_ahead
        self._diagnostics: dict[str, float] = {}

    @property
    def command_preview(self) -> Callable[[float], Command] | None:
        return self._timeline

    @command_preview.setter
    def command_preview(self, timeline: Callable[[float], Command] | None) -> None:
        """The simulation hands the scenario's timeline over; the rider gets it with the
        path's yaw rate laid over it."""
        self._timeline = timeline
        self.inner.command_preview = None if timeline is None else self._preview

    def _preview(self, t: float) -> Command:
        assert self._timeline is not None
        return self._steered(self._timeline(t), t)

    def turn_ahead(self, t: float) -> float:
        """The yaw rate [rad/s] the law expects to ask at ``t`` [s]: its latest plus the
        change of the path's curvature between where the rider is and where she will be
        by then at her speed, :math:`v (\\kappa_p(s + v (t - t_0)) - \\kappa_p(s))`."""
        if t < self.path.start:
            return 0.0
        if self._ahead is None or t <= self._ahead[0]:
            return self._yaw_rate
        time, arc, speed, curvature = self._ahead
        geometry = self.geometry
        later = float(geometry.curvature[geometry.at_arc(arc + speed * (t - time))])
        wanted = self._yaw_rate + speed * (later - curvature)
        if self.max_yaw_rate is not None:
            bound = self.max_yaw_rate(speed)
            wanted = max(-bound, min(bound, wanted))
        return wanted

    def _steered(self, command: Command, t: float) -> Command:
        if t < self.path.start:
            return command
        return command.model_copy(update={"yaw_rate": self._yaw_rate})

    def yaw_rate(self, sensors: SensorPacket) -> float:
        """The law's yaw rate at this packet [rad/s] (the last one without a new VIO)."""
        vio = sensors.vio
        if vio is None:
            return self._yaw_rate
        lag = max(0.0, sensors.time - vio.stamp)
        point = np.asarray(vio.position[:2], dtype=float) + lag * np.asarray(vio.velocity[:2])
        heading = vio.yaw + lag * vio.yaw_rate
        speed = math.cos(heading) * vio.velocity[0] + math.sin(heading) * vio.velocity[1]
        if self._frame is None:
            self._frame = PathFrame(point[0], point[1], heading)
        point = self._frame.to_path(point)
        heading = self._frame.heading_to_path(heading)
        geometry = self.geometry
        self._index = geometry.nearest(point, self._index)
        cross, path_heading = geometry.errors(point, self._index)
        ahead = geometry.at_arc(geometry.arc[self._index] + max(speed, 0.0) * self.preview)
        error = math.remainder(heading - path_heading, 2.0 * math.pi)
        wanted = path_yaw_rate(cross, error, float(geometry.curvature[ahead]), speed, self.distance)
        arc = float(geometry.arc[ahead])
        self._ahead = (sensors.time, arc, max(speed, 0.0), float(geometry.curvature[ahead]))
        if self.max_yaw_rate is not None:
            bound = self.max_yaw_rate(speed)
            wanted = max(-bound, min(bound, wanted))
        self._diagnostics.update(cross_track=cross, path_yaw_rate=wanted)
        return wanted

    def hold_speed(self) -> None:
        self.inner.hold_speed()

    def reset(self, sensors: SensorPacket) -> None:
        self._index = None
        self._frame = None
        self._yaw_rate = 0.0
        self._ahead = None
        self.inner.reset(sensors)

    def update(self, sensors: SensorPacket, command: Command) -> MotorCommand:
        if sensors.time >= self.path.start:
            self._yaw_rate = self.yaw_rate(sensors)
        return self.inner.update(sensors, self._steered(command, sensors.time))

    def diagnostics(self) -> dict[str, float]:
        return {**self.inner.diagnostics(), **self._diagnostics}

    def summary(self) -> dict[str, Any]:
        return self.inner.summary()

    def estimate(self) -> Any:
        return self.inner.estimate()


def follow_path(
    inner: Controller, path: CirclePath | SlalomPath, board: Board | None
) -> PathFollowing:
    """``inner`` following ``path`` on ``board``, its yaw rate bounded by what the board
    steers (:func:`~ridempc.boards.steering.steering_limits`)."""
    limits = steering_limits(board)
    return PathFollowing(inner, path, limits.max_yaw_rate if limits is not None else None)
