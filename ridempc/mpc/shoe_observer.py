"""What the Hovershoes' reduced model misses under a rider: where each foot stands along its
shoe (eq. (4)'s balance) and the drag on each shoe (eq. (8)'s), the MPC's disturbance estimate.

**Where the foot stands.** The rider's feet tell the estimator each shoe's pitch, heading
and velocity, but not where the shoe's pitch axis lies under the foot: the platform
estimate's origin is the foot's own contact centroid :math:`c`
(:mod:`ridempc.estimation.board`). A foot that stands :math:`d` [m] ahead of the axis presses
the nose down with :math:`d\\,N` [N m] (:math:`N` [N] its load), which the MPC's model, with
:math:`d = 0`, does not see: a foot 4 cm ahead of the axis under a 160 N load is 6.4 N m, a
static pitch of :math:`6.4 / c_1 = 0.14` rad and a speed-up of :math:`c_4\\,0.14/m = 3`
m/s^2 (the offset start: the right shoe, 3 cm behind the left, ran off in 0.2 s). Per shoe,
eq. (4) with the rider's torque about the foot's centroid :math:`u_\\theta(c)` and the
offset's:

.. math::

    J_\\theta \\ddot\\theta + c_2 \\dot\\theta + c_1 \\theta = u_\\theta(c) + d\\,N,
    \\qquad u_\\theta(c) = y_P^\\top \\sum_i (p_i - c) \\times (-F_i),
    \\qquad N = \\sum_i F_{i,z},

with :math:`p_i` [m] the foot's contact sites and :math:`F_i` [N] the support's force on
them (the whole-body QP's, which the motors apply), :math:`y_P` the shoe's lateral axis and
:math:`\\theta` [rad] its estimated pitch (nose down positive).

**Drag.** Eq. (8) with the rider's push (:class:`~ridempc.trajopt.platforms.HovershoesBoard`)
and a force :math:`D` [N] along the heading that it leaves out (rolling resistance, and what
the firmware does beyond :math:`c_4\\theta`):

.. math:: m_s \\dot v = c_4 \\theta + P + D, \\qquad
    P = -\\sum_i x_P^\\top F_i,

:math:`x_P` the shoe's forward axis, :math:`m_s` [kg] the bare shoe. Without it the MPC held
its shoes level at 0.5 m/s and the speed sagged to 0.35 m/s.

**Slopes.** The ground's slope under each shoe, estimated from its velocity
(:mod:`ridempc.mpc.slope`), adds its pull :math:`G = -(m_s g + N)\\sin\\hat\\alpha` to
:math:`D` at once; the fit below finds only the rest. What the fit finds on one slope is not
another's (down 13 deg it settles at +19 N, on level ground at -2 N, seed 0; and while the
slope estimate moves, the fit takes in the pull the estimate has not yet read): each time
the slope estimate under a shoe has moved ``SLOPE_CHANGE`` from where it was at the last such
change, the shoe's drag fit forgets as if ``MEMORY`` had passed once per ``SLOPE_CHANGE`` of it
(:math:`\\lambda = e^{-|\\Delta\\hat\\alpha| / \\alpha_c}`), so it is refitted on the new
ground within a few tenths of a second rather than holding the old pull for a second (which
held the shoes back at the slope's foot).

**Fitting.** The pitch, the speed, the torque, the push and the load pass through the same
critically damped second-order low-pass at ``FILTER_HZ``, whose states give the filtered
angle, speed and their rates without differentiating noise. The residuals of the two
balances are fitted by least squares with exponential forgetting over ``MEMORY``
(:math:`\\lambda = e^{-\\Delta t / T}`), to a constant offset and a constant drag:

.. math::

    b_k = J_\\theta \\ddot{\\bar\\theta}_k + c_2 \\dot{\\bar\\theta}_k
        + c_1 \\bar\\theta_k - \\bar u_{\\theta,k}, \\qquad
    d = \\frac{\\sum_k \\lambda^{K-k} \\bar N_k b_k}{\\sum_k \\lambda^{K-k} \\bar N_k^2},
    \\qquad
    D = \\frac{\\sum_k \\lambda^{K-k} (m_s \\dot{\\bar v}_k - c_4 \\bar\\theta_k
        - \\bar P_k)}{\\sum_k \\lambda^{K-k}},

over the ticks with a load over ``MIN_LOAD``, :math:`d` held within ``LIMIT``. Early in a
ride the fit rests on the few ticks it has and finds a misplaced foot within a tenth of a
second; later it averages over :math:`T` (fitted tick by tick, the offset would ring with
the shoes' 4 Hz pitch and feed it).

**Use.** The MPC sees each shoe's axis :math:`d` behind its foot (:meth:`ShoeObserver.shift`),
wants it :math:`d` behind where the reference puts the foot
(:meth:`ShoeObserver.shift_reference`: the library's shoes carry their feet over their axes,
and held to them a rider on staggered shoes would scissor her feet to line the axes up), and
has :math:`D` in its speed equations (:meth:`ShoeObserver.speed_drift`); the whole-body QP
has it in its rolling platforms' acceleration (:meth:`ShoeObserver.drift`): down a slope the
pull on a shoe is some 50 N, and a QP that leaves it out takes a nose-up shoe for one that
brakes at :math:`c_4\theta / m_s` (20 m/s^2 at -0.13 rad) and moves the feet for it.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation.state import BoardEstimate, EstimatedState
from ridempc.mpc.slope import SlopeEstimator
from ridempc.mpc.slope_trim import SlopeSpeedTrim
from ridempc.mpc.state_map import forward_speed
from ridempc.trajopt.platforms import HovershoesBoard

__all__ = ["FILTER_HZ", "LIMIT", "MEMORY", "MIN_LOAD", "SLOPE_CHANGE", "WARM_UP", "ShoeObserver"]

Array = NDArray[np.float64]
FILTER_HZ: float = 4.0  # [Hz] natural frequency of the critically damped low-pass
LIMIT: float = 0.08  # [m] |d| at most: half of Cassie's toe line
MIN_LOAD: float = 20.0  # [N] below this filtered load the offset is not updated
MEMORY: float = 1.0  # [s] forgetting time of the least squares
WARM_UP: float = 0.05  # [s] the low-pass settles from its first sample before it is fitted
# [rad] a change of the ground under a shoe: the slope trim's gate (3 deg, ten times what the
# slope estimate reads on level ground), so 13 deg forgets the old slope's drag four times over
SLOPE_CHANGE: float = math.radians(3.0)


class _SecondOrder:
    """Critically damped low-pass :math:`\\ddot y = \\omega^2 (u - y) - 2\\omega\\dot y`,
    semi-implicit Euler, per channel; starts at its first input, at rest."""

    def __init__(self, hz: float) -> None:
        self.omega = 2.0 * math.pi * hz
        self.y: Array | None = None
        self.dy = np.zeros(0)
        self.ddy = np.zeros(0)

    def __call__(self, u: Array, dt: float) -> None:
        if self.y is None:
            self.y, self.dy, self.ddy = u.copy(), np.zeros_like(u), np.zeros_like(u)
            return
        w = self.omega
        self.ddy = w * w * (u - self.y) - 2.0 * w * self.dy
        self.dy = self.dy + dt * self.ddy
        self.y = self.y + dt * self.dy


class ShoeObserver:
    """Each foot's offset ahead of its shoe's pitch axis and each shoe's drag (the module
    docstring).

    Args:
        shoes: The shoes' identified model as the MPC has it.
        site_platform: The platform each contact site stands on (-1: none), WBC site order.
        hz: The low-pass's natural frequency [Hz].
        memory: The least squares' forgetting time [s].
        warm_up: Time the low-pass runs before its output is fitted [s].
    """

    def __init__(
        self,
        shoes: HovershoesBoard,
        site_platform: Sequence[int],
        hz: float = FILTER_HZ,
        memory: float = MEMORY,
        warm_up: float = WARM_UP,
    ) -> None:
        self.params, self.shoe_mass = shoes.reduced, shoes.shoe_mass
        self.site_platform = np.asarray(site_platform, dtype=np.int64)
        self.platforms = int(self.site_platform.max()) + 1
        self._sites = [
            np.flatnonzero(self.site_platform == k).tolist() for k in range(self.platforms)
        ]
        self._filter = _SecondOrder(hz)
        self.memory, self.warm_up = memory, warm_up
        self._time: float | None = None
        self._start = 0.0
        n = self.platforms
        self._moment = np.zeros(n)  # [N^2 m] sum of w N b
        self._load = np.zeros(n)  # [N^2] sum of w N^2
        self._force = np.zeros(n)  # [N] sum of w (m v' - c4 theta - P)
        self._weight = np.zeros(n)  # [-] sum of w
        self.offsets = np.zeros(n)  # [m] d per platform
        self.drag = np.zeros(n)  # [N] D per platform
        self.slopes = SlopeEstimator(n)  # the ground's slope under each shoe
        self._fitted_on = [0.0] * n  # [rad] the slope at the drag fit's last forgetting
        self.trim = SlopeSpeedTrim()  # the reference's speed trim on a slope (mpc/slope_trim.py)

    def update(
        self,
        estimate: EstimatedState,
        site_positions: Array,
        site_forces: Array,
    ) -> None:
        """Fold in one tick: the estimate's platforms and the forces the rider applied on its
        sites since the last one (world, shapes (sites, 3)); updates :attr:`offsets` [m] and
        :attr:`drag` [N]."""
        boards = estimate.boards
        n = self.platforms
        if len(boards) != n:
            return
        # Plain floats: two shoes of two sites each, where NumPy's per-call cost dominates.
        positions, forces = site_positions.tolist(), site_forces.tolist()
        pitch, speed, torque, push, load = ([0.0] * n for _ in range(5))
        for k, board in enumerate(boards):
            cx, cy, cz = board.position.tolist()
            cos, sin = math.cos(board.yaw), math.sin(board.yaw)
            fx = fy = fz = tau = 0.0
            for i in self._sites[k]:
                (px, py, pz), (gx, gy, gz) = positions[i], forces[i]  # g: on the rider
                rx, ry, rz = px - cx, py - cy, pz - cz
                # lateral axis . (r x (-g)): the rider's torque on the shoe about its axis
                tau -= cos * (rz * gx - rx * gz) - sin * (ry * gz - rz * gy)
                fx, fy, fz = fx + gx, fy + gy, fz + gz
            torque[k] = tau
            push[k] = -(math.cos(board.pitch) * (cos * fx + sin * fy) - math.sin(board.pitch) * fz)
            load[k] = fz
            pitch[k] = board.pitch
            speed[k] = forward_speed(board)
        if self._time is None:
            self._start = self._time = estimate.time
        dt = estimate.time - self._time
        self._time = estimate.time
        slopes = self.slopes.update(estimate.time, boards)
        grade = self.slopes.gravity_drag
        pulls = [grade(a, self.shoe_mass, w) for a, w in zip(slopes, load, strict=True)]
        self._filter(np.array(pitch + speed + torque + push + load + pulls), dt)
        f, p = self._filter, self.params
        assert f.y is not None
        y, dy, ddy = f.y.tolist(), f.dy.tolist(), f.ddy.tolist()
        theta, theta_dot, theta_ddot = y[:n], dy[:n], ddy[:n]
        accel = dy[n : 2 * n]
        u, pushed, weight = y[2 * n : 3 * n], y[3 * n : 4 * n], y[4 * n : 5 * n]
        pulled = y[5 * n :]  # the slope's pull as filtered as the speed it changes
        if estimate.time - self._start < self.warm_up:
            return
        forget = math.exp(-dt / self.memory)
        for k in range(n):
            self._moment[k] *= forget
            self._load[k] *= forget
            self._force[k] *= forget
            self._weight[k] *= forget
            change = abs(slopes[k] - self._fitted_on[k])
            if change > SLOPE_CHANGE:  # new ground: the drag fit forgets what it had
                self._fitted_on[k] = slopes[k]
                self._force[k] *= math.exp(-change / SLOPE_CHANGE)
                self._weight[k] *= math.exp(-change / SLOPE_CHANGE)
            uphill = self.slopes.gravity_drag(slopes[k], self.shoe_mass, weight[k])
            if weight[k] > MIN_LOAD:
                balance = p.J_theta * theta_ddot[k] + p.c2 * theta_dot[k] + p.c1 * theta[k] - u[k]
                residual = self.shoe_mass * accel[k] - p.c4 * theta[k] - pushed[k] - pulled[k]
                self._moment[k] += weight[k] * balance
                self._load[k] += weight[k] * weight[k]
                self._force[k] += residual
                self._weight[k] += 1.0
            if self._load[k] > 0.0:
                self.offsets[k] = min(max(self._moment[k] / self._load[k], -LIMIT), LIMIT)
                self.drag[k] = self._force[k] / self._weight[k] + uphill

    def frozen(self) -> ShoeObserver:
        """A copy whose offsets and drags stay as they are now, whatever later updates
        do to this one's (an MPC problem built beside the control loop reads them)."""
        out = copy.copy(self)
        out.offsets, out.drag = self.offsets.copy(), self.drag.copy()
        out.trim = copy.copy(self.trim)
        return out

    def speed_drift(self, c: Array, dt: float, speeds: Sequence[int]) -> Array:
        """The MPC's affine terms ``c`` (N x nx) with each shoe's drag in its speed equation,
        :math:`c_{k,v} \\mathrel{+}= D\\,\\Delta t / m_s` (``speeds``: each platform's speed
        index; ``dt`` [s] the MPC's step). The drag's share of the position over one step,
        :math:`D\\,\\Delta t^2 / 2 m_s`, is left out: under 1 mm at 5 N."""
        out = np.array(c, dtype=float)
        out[:, list(speeds)] += self.drag * dt / self.shoe_mass
        return out

    def drift(self, boards: Sequence[BoardEstimate]) -> tuple[Array, ...]:
        """Each shoe's drag as the acceleration it gives the bare shoe along its heading,
        :math:`D / m_s` [m/s^2] (world, one 3-vector per platform): what the whole-body QP's
        rolling platforms (:mod:`~ridempc.wbc.platforms`, eq. (8) without :math:`D`) add to
        the feet's acceleration on them."""
        if len(boards) != self.platforms:
            return ()
        return tuple(
            (d / self.shoe_mass) * np.array([math.cos(b.yaw), math.sin(b.yaw), 0.0])
            for b, d in zip(boards, self.drag.tolist(), strict=True)
        )

    def shift_reference(self, states: Array, columns: Sequence[Sequence[int]]) -> Array:
        """A copy of the MPC's reference ``states`` (nodes x nx) with each shoe moved
        :math:`d` back along its heading: ``columns`` holds each platform's (x, y, heading,
        ...) state indices."""
        out = np.array(states, dtype=float)
        for (x, y, heading, *_), d in zip(columns, self.offsets, strict=True):
            out[:, x] -= d * np.cos(out[:, heading])
            out[:, y] -= d * np.sin(out[:, heading])
        return out

    def shift(self, estimate: EstimatedState) -> EstimatedState:
        """The estimate with each platform's origin on its shoe's axis: :math:`d` behind the
        foot along the shoe's heading."""
        if len(estimate.boards) != self.platforms:
            return estimate
        boards: list[BoardEstimate] = []
        for board, d in zip(estimate.boards, self.offsets, strict=True):
            heading = np.array([math.cos(board.yaw), math.sin(board.yaw), 0.0])
            boards.append(replace(board, position=board.position - d * heading))
        return replace(estimate, boards=tuple(boards))
