"""The local planner: a Timed Elastic Band (Roesmann et al.) as a CasADi NLP.

The band is :math:`N` poses :math:`s_i = (x_i, y_i, \\theta_i)` and the :math:`N - 1` times
:math:`\\Delta T_i` between them, from the rider's pose to a local goal on the global path
``LOOK_AHEAD`` ahead. It minimises

.. math:: \\sum_i \\Delta T_i
    + w_{nh} \\sum_i \\left[ (\\cos\\theta_i + \\cos\\theta_{i+1}) \\Delta y_i
      - (\\sin\\theta_i + \\sin\\theta_{i+1}) \\Delta x_i \\right]^2
    + w_{b} \\sum_i \\max(0, -\\Delta x_i \\cos\\theta_i - \\Delta y_i \\sin\\theta_i)^2
    + w_{r} \\sum_i \\max(0, r_{min} |\\Delta\\theta_i| - \\lVert \\Delta p_i \\rVert)^2
    + w_{o} \\sum_{i, k} \\max(0, d_{min} - d(\\overline{p_i p_{i+1}}, o_k))^2
    + w_{a} \\sum_i (v_{i+1} - v_i)^2 + w_{\\omega} \\sum_i (\\omega_{i+1} - \\omega_i)^2
    + w_{e} \\sum_i (\\Delta T_{i+1} - \\Delta T_i)^2

(time; the non-holonomic arc condition, the shoes move along their heading; forward
driving; a car-like turning radius; the distance of each obstacle point :math:`o_k` to
each *segment* of the band, not only to its poses; smooth speeds and turns, from the
current ones; evenly spaced times), subject to
:math:`\\lVert \\Delta p_i \\rVert \\le v_{max} \\Delta T_i` and
:math:`|\\Delta\\theta_i| \\le \\omega_{max} \\Delta T_i` and forward motion. The NLP is
built once with the start, goal and obstacles as parameters and solved by IPOPT,
warm-started from the last band. The band's first half second gives the riding controller
its speed and yaw-rate command.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np
from numpy.typing import NDArray

__all__ = ["LOOK_AHEAD", "Band", "TebPlanner", "TebSettings"]

Array = NDArray[np.float64]

LOOK_AHEAD: float = 1.75  # [m] the Hovershoes paper's local goal distance
FAR: float = 1.0e3  # [m] where unused obstacle slots are parked


@dataclass(frozen=True)
class TebSettings:
    """Weights and limits of the band.

    Attributes:
        poses: Number of poses :math:`N`.
        v_max: Top speed [m/s].
        omega_max: Top yaw rate [rad/s].
        d_min: Closest a band segment may pass an obstacle point [m]: the rider's radius
            and a margin.
        r_min: Car-like turning radius [m].
        obstacles: Obstacle points the NLP takes (the nearest ones).
        w_nonholonomic: Weight of the arc condition.
        w_backward: Weight of driving backwards.
        w_radius: Weight of turning tighter than ``r_min``.
        w_obstacle: Weight of an obstacle within ``d_min``.
        w_speed_change: Weight of speed changes between segments.
        w_turn_change: Weight of yaw-rate changes between segments.
        w_even: Weight of unequal times between poses (keeps the band evenly discretised,
            not squeezed to the shortest steps at one end and stretched at the other).
        max_iter: IPOPT iterations per update.
    """

    poses: int = 10
    v_max: float = 0.5
    omega_max: float = 0.35
    d_min: float = 0.5
    r_min: float = 0.6
    obstacles: int = 30
    w_nonholonomic: float = 1000.0
    w_backward: float = 1000.0
    w_radius: float = 50.0
    w_obstacle: float = 200.0
    w_speed_change: float = 2.0
    w_turn_change: float = 1.0
    w_even: float = 10.0
    max_iter: int = 40


@dataclass(frozen=True)
class Band:
    """A solved band.

    Attributes:
        poses: (x, y, theta) per pose [m, m, rad], shape (N, 3).
        dt: Time between poses [s], shape (N - 1,).
        success: Whether IPOPT converged (or stopped at its iteration limit feasibly).
        solve_time: Wall time of the solve [s].
    """

    poses: Array
    dt: Array
    success: bool
    solve_time: float

    def command(self, horizon: float) -> tuple[float, float]:
        """Mean forward speed [m/s] and yaw rate [rad/s] over the band's first ``horizon``
        seconds (at least its first segment)."""
        speeds, turns = self.speeds()
        times = np.concatenate([[0.0], np.cumsum(self.dt)])
        within = np.clip(np.minimum(times[1:], horizon) - times[:-1], 0.0, None)
        within[0] = max(within[0], 1e-9)
        weights = within / within.sum()
        return float(weights @ speeds), float(weights @ turns)

    def speeds(self) -> tuple[Array, Array]:
        """Forward speed [m/s] and yaw rate [rad/s] of each segment."""
        delta = np.diff(self.poses, axis=0)
        forward = delta[:, 0] * np.cos(self.poses[:-1, 2]) + delta[:, 1] * np.sin(
            self.poses[:-1, 2]
        )
        return forward / self.dt, delta[:, 2] / self.dt

    def clearance(self, obstacles: Array) -> float:
        """Smallest distance of the band's segments to the obstacle points [m]."""
        if len(obstacles) == 0:
            return math.inf
        a, b = self.poses[:-1, None, :2], self.poses[1:, None, :2]
        o = obstacles[None, :, :2]
        ab = b - a
        t = np.clip(((o - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-12), 0.0, 1.0)
        return float(np.linalg.norm(a + t[..., None] * ab - o, axis=-1).min())


class TebPlanner:
    """The band's NLP, built once; :meth:`solve` per update, warm-started.

    Args:
        settings: Weights and limits.
    """

    def __init__(self, settings: TebSettings | None = None) -> None:
        self.settings = s = settings or TebSettings()
        n, k = s.poses, s.obstacles
        x = ca.SX.sym("x", 3, n)
        dt = ca.SX.sym("dt", n - 1)
        start = ca.SX.sym("start", 3)
        goal = ca.SX.sym("goal", 3)
        obstacles = ca.SX.sym("obstacles", 2, k)
        speed0 = ca.SX.sym("speed0")
        turn0 = ca.SX.sym("turn0")
        cost = ca.sum1(dt)
        g, lbg, ubg = [x[:, 0] - start, x[:2, n - 1] - goal[:2]], [0.0] * 5, [0.0] * 5
        speeds, turns = [], []
        for i in range(n - 1):
            dx, dy = x[0, i + 1] - x[0, i], x[1, i + 1] - x[1, i]
            dth = x[2, i + 1] - x[2, i]
            c0, s0 = ca.cos(x[2, i]), ca.sin(x[2, i])
            c1, s1 = ca.cos(x[2, i + 1]), ca.sin(x[2, i + 1])
            cost += s.w_nonholonomic * ((c0 + c1) * dy - (s0 + s1) * dx) ** 2
            forward = dx * c0 + dy * s0
            cost += s.w_backward * ca.fmax(0.0, -forward) ** 2
            length = ca.sqrt(dx**2 + dy**2 + 1e-9)
            cost += s.w_radius * ca.fmax(0.0, s.r_min * ca.fabs(dth) - length) ** 2
            speeds.append(forward / dt[i])
            turns.append(dth / dt[i])
            g += [
                length - s.v_max * dt[i],
                dth - s.omega_max * dt[i],
                -dth - s.omega_max * dt[i],
                -forward,  # the shoes ride forwards
            ]
            lbg += [-ca.inf] * 4
            ubg += [0.0] * 4
            a = x[:2, i]
            ab = x[:2, i + 1] - a
            ao = obstacles - ca.repmat(a, 1, k)
            t = ca.fmin(1.0, ca.fmax(0.0, (ab.T @ ao) / (ca.sumsqr(ab) + 1e-9)))
            nearest = ca.repmat(a, 1, k) + ab @ t
            d = ca.sqrt(ca.sum1((nearest - obstacles) ** 2) + 1e-9)
            cost += s.w_obstacle * ca.sumsqr(ca.fmax(0.0, s.d_min - d))
        for i in range(n - 2):
            cost += s.w_speed_change * (speeds[i + 1] - speeds[i]) ** 2
            cost += s.w_turn_change * (turns[i + 1] - turns[i]) ** 2
            cost += s.w_even * (dt[i + 1] - dt[i]) ** 2
        cost += s.w_speed_change * (speeds[0] - speed0) ** 2
        cost += s.w_turn_change * (turns[0] - turn0) ** 2
        cost += 10.0 * (1.0 - ca.cos(x[2, n - 1] - goal[2]))
        variables = ca.veccat(x, dt)
        parameters = ca.veccat(start, goal, obstacles, speed0, turn0)
        self._solver = ca.nlpsol(
            "teb",
            "ipopt",
            {"x": variables, "p": parameters, "f": cost, "g": ca.vertcat(*g)},
            {
                "ipopt.print_level": 0,
                "ipopt.sb": "yes",
                "ipopt.max_iter": s.max_iter,
                "ipopt.tol": 1e-4,
                "ipopt.acceptable_tol": 1e-2,
                # a warm-started band is near its optimum: the adaptive barrier takes 10
                # iterations (median) where the monotone one takes 14, the same commands
                "ipopt.mu_strategy": "adaptive",
                "ipopt.warm_start_init_point": "yes",
                "print_time": False,
            },
        )
        self._lbg, self._ubg = lbg, ubg
        lbx = np.full(3 * n + n - 1, -np.inf)
        ubx = np.full(3 * n + n - 1, np.inf)
        lbx[3 * n :] = 0.02  # [s] a band step of at least 20 ms
        ubx[3 * n :] = 1.0
        self._lbx, self._ubx = lbx, ubx
        self._last: Band | None = None

    def reset(self) -> None:
        self._last = None

    def _guess(self, start: Array, goal: Array) -> tuple[Array, Array]:
        """The last band from the pose nearest the rider on (the poses it has passed are
        dropped) to the new goal, resampled to ``N`` poses evenly along its length; a
        straight line when there is no last band or its goal moved far."""
        n, v_max = self.settings.poses, self.settings.v_max
        last = self._last
        if last is not None and np.linalg.norm(last.poses[-1, :2] - goal[:2]) < 1.0:
            nearest = int(np.argmin(np.linalg.norm(last.poses[:, :2] - start[:2], axis=1)))
            chain = np.vstack([start, last.poses[nearest + 1 : -1], goal])
            chain[:, 2] = start[2] + np.unwrap(chain[:, 2] - start[2])
            arc = np.concatenate(
                [[0.0], np.cumsum(np.linalg.norm(np.diff(chain[:, :2], axis=0), axis=1))]
            )
            if arc[-1] > 1e-3:
                at = np.linspace(0.0, arc[-1], n)
                poses = np.column_stack([np.interp(at, arc, chain[:, k]) for k in range(3)])
                speed = float(np.clip(np.mean(np.abs(last.speeds()[0])), 0.2 * v_max, v_max))
                return poses, np.full(n - 1, max(0.02, arc[-1] / (n - 1) / speed))
        alpha = np.linspace(0.0, 1.0, n)[:, None]
        poses = (1.0 - alpha) * start[None, :] + alpha * goal[None, :]
        heading = math.atan2(goal[1] - start[1], goal[0] - start[0])
        poses[1:-1, 2] = start[2] + _wrap(heading - start[2])
        distance = float(np.linalg.norm(goal[:2] - start[:2]))
        dt = np.full(n - 1, max(0.05, distance / (n - 1) / (0.8 * v_max)))
        return poses, dt

    def solve(
        self, start: Array, goal: Array, obstacles: Array, speed: float = 0.0, turn: float = 0.0
    ) -> Band:
        """The band from ``start`` to ``goal`` (x, y, theta) [m, m, rad] past ``obstacles``
        (world (x, y) [m], the nearest ``settings.obstacles`` are used), starting at forward
        ``speed`` [m/s] and yaw rate ``turn`` [rad/s]."""
        s = self.settings
        start = np.asarray(start, dtype=float)
        goal = np.asarray(goal, dtype=float).copy()
        goal[2] = start[2] + _wrap(goal[2] - start[2])  # the same turn, not a full one more
        poses, dt = self._guess(start, goal)
        slots = np.full((2, s.obstacles), FAR)
        if len(obstacles):
            middle = 0.5 * (start[:2] + goal[:2])
            order = np.argsort(np.linalg.norm(obstacles[:, :2] - middle, axis=1))
            chosen = obstacles[order[: s.obstacles], :2]
            slots[:, : len(chosen)] = chosen.T
        p = np.concatenate([start, goal, slots.T.reshape(-1), [speed, turn]])
        began = time.perf_counter()
        try:
            result = self._solver(
                x0=np.concatenate([poses.reshape(-1), dt]),
                p=p,
                lbx=self._lbx,
                ubx=self._ubx,
                lbg=self._lbg,
                ubg=self._ubg,
            )
        except RuntimeError:  # CasADi's own error (a NaN in its evaluation): a failed band
            self._last = None
            return Band(poses, dt, success=False, solve_time=time.perf_counter() - began)
        elapsed = time.perf_counter() - began
        status = self._solver.stats()["return_status"]
        z = np.asarray(result["x"]).reshape(-1)
        n = s.poses
        g = np.asarray(result["g"]).reshape(-1)
        violation = max(
            float(np.max(np.abs(g[:5]))), float(np.max(g[5:], initial=0.0))
        )  # the fixed ends, then the speed limits (<= 0)
        converged = status in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
        band = Band(
            poses=z[: 3 * n].reshape(n, 3),
            dt=z[3 * n :],
            success=bool(np.isfinite(z).all())
            and (converged or (status == "Maximum_Iterations_Exceeded" and violation < 1e-3)),
            solve_time=elapsed,
        )
        if band.success:
            self._last = band
        return band


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
