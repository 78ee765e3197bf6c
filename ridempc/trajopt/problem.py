"""A multiple-shooting NLP, built once, solved by IPOPT: the types shared by every pair.

Building and solving are separate (as in pink's ``build_ik``/``solve_ik``): a builder for a
robot-board pair returns a :class:`TrajectoryProblem` (the symbolic NLP, its bounds, its
scaling, and the continuous dynamics it discretises), which can be inspected and tested
without a solver; :func:`solve_trajectory` hands it to ``casadi.nlpsol('ipopt')`` and returns
a :class:`TrajectorySolution` recording the status, iterations, times and the largest
dynamics-constraint violation.

**Transcription.** Each shooting interval :math:`[t_k, t_k + h]` holds its input
:math:`u_k` constant and is integrated by the Hermite-Simpson rule (fourth order, the
collocation form of Simpson's rule), with a midpoint state :math:`x_{k+1/2}` as a variable:

.. math::

    x_{k+1/2} = \\tfrac12 (x_k + x_{k+1}) + \\tfrac{h}{8} (f_k - f_{k+1}), \\qquad
    x_{k+1} = x_k + \\tfrac{h}{6} (f_k + 4 f_{k+1/2} + f_{k+1})

with :math:`f_\\bullet = f(x_\\bullet, u_k, p_k)`. Unlike an RK4 step, whose stages nest
four evaluations of :math:`f` inside each other, every :math:`f` here takes decision
variables directly, so the Hessian of the Lagrangian is a sum of small Hessians of
:math:`f`; with RK4 the exact Hessian of one CyberDog2 interval had 640 000 nodes and
building the NLP took 40 s, with Hermite-Simpson it takes a few seconds.

Decision variables are ordered interval by interval, :math:`w = (x_0, u_0, x_{1/2}, x_1,
u_1, \\dots, x_N)`, which keeps the KKT matrix banded for MUMPS, and are scaled,
:math:`x = s_x \\odot \\tilde x`, :math:`u = s_u \\odot \\tilde u`, so that IPOPT sees
quantities of order one (forces in units of the robot's weight per foot, and so on).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.errors import RidempcError
from ridempc.interrupts import casadi_solve

__all__ = [
    "NodeSpec",
    "NodeTerms",
    "TrajectoryFailed",
    "TrajectoryProblem",
    "TrajectorySolution",
    "assemble_problem",
    "collocation_defect",
    "dynamics_residual",
    "solve_trajectory",
]

Array = NDArray[np.float64]


class TrajectoryFailed(RidempcError):
    """IPOPT did not return a solution to store."""

    def __init__(self, name: str, status: str, iterations: int) -> None:
        self.name = name
        self.status = status
        self.iterations = iterations
        super().__init__(f"entry '{name}': IPOPT returned {status} after {iterations} iterations")


def collocation_defect(rates: ca.Function, dt: float) -> ca.Function:
    """Hermite-Simpson defects of one interval (2 nx): midpoint and end.

    Args:
        rates: :math:`f(x, u, p)`.
        dt: Interval length :math:`h` [s].

    Returns:
        Function ``(x_k, x_mid, x_next, u, p) -> defect``, zero on an exact collocation.
    """
    nx = rates.size1_in(0)
    x, mid, nxt = ca.SX.sym("x", nx), ca.SX.sym("mid", nx), ca.SX.sym("next", nx)
    u = ca.SX.sym("u", rates.size1_in(1))
    p = ca.SX.sym("p", rates.size1_in(2))
    f0, fm, f1 = rates(x, u, p), rates(mid, u, p), rates(nxt, u, p)
    defect = ca.vertcat(
        mid - 0.5 * (x + nxt) - dt / 8.0 * (f0 - f1),
        nxt - x - dt / 6.0 * (f0 + 4.0 * fm + f1),
    )
    return ca.Function("collocation_defect", [x, mid, nxt, u, p], [defect])


@dataclass(frozen=True)
class TrajectoryProblem:
    """A built NLP.

    Attributes:
        name: Entry name.
        variables: Decision vector :math:`w` (scaled), CasADi MX.
        objective: Cost (eq. 16 for the skateboard).
        constraints: Every constraint, stacked (the defects first).
        lbw: Lower bounds of :math:`w`.
        ubw: Upper bounds of :math:`w`.
        lbg: Lower bounds of the constraints.
        ubg: Upper bounds of the constraints.
        state_names: Names of the state components.
        input_names: Names of the input components.
        state_scale: :math:`s_x`.
        input_scale: :math:`s_u`.
        times: Node times [s] (N + 1).
        parameters: Per-interval dynamics parameters (the mode data), N x n_p.
        rates: Continuous dynamics :math:`\\dot x = f(x, u, p)` (CasADi function).
        defect: Hermite-Simpson defects of one interval (see :func:`collocation_defect`).
        build_time: Seconds spent building [s].
        metadata: What the library stores besides the arrays (target, schedule, options).
    """

    name: str
    variables: ca.MX
    objective: ca.MX
    constraints: ca.MX
    lbw: Array
    ubw: Array
    lbg: Array
    ubg: Array
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    state_scale: Array
    input_scale: Array
    times: Array
    parameters: Array
    rates: ca.Function
    defect: ca.Function
    build_time: float
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def n_intervals(self) -> int:
        return len(self.times) - 1

    @property
    def nx(self) -> int:
        return len(self.state_names)

    @property
    def nu(self) -> int:
        return len(self.input_names)

    @property
    def dt(self) -> float:
        return float(self.times[1] - self.times[0])

    def pack(self, states: Array, inputs: Array, midpoints: Array | None = None) -> Array:
        """Physical states (N+1 x nx), inputs (N x nu) and midpoint states (N x nx, default
        the mean of each interval's ends) -> scaled decision vector."""
        states = np.asarray(states, dtype=float)
        if midpoints is None:
            midpoints = 0.5 * (states[1:] + states[:-1])
        xs = states / self.state_scale
        us = np.asarray(inputs, dtype=float) / self.input_scale
        ms = np.asarray(midpoints, dtype=float) / self.state_scale
        body = np.hstack([xs[:-1], us, ms])
        return np.concatenate([body.ravel(), xs[-1]])

    def unpack(self, w: Array) -> tuple[Array, Array, Array]:
        """Scaled decision vector -> physical states (N+1 x nx), inputs (N x nu) and
        midpoint states (N x nx)."""
        w = np.asarray(w, dtype=float).ravel()
        n, nx, nu = self.n_intervals, self.nx, self.nu
        body = w[: n * (2 * nx + nu)].reshape(n, 2 * nx + nu)
        states = np.vstack([body[:, :nx], w[n * (2 * nx + nu) :][None, :]]) * self.state_scale
        inputs = body[:, nx : nx + nu] * self.input_scale
        return states, inputs, body[:, nx + nu :] * self.state_scale


@dataclass(frozen=True)
class TrajectorySolution:
    """What IPOPT returned for one problem.

    Attributes:
        name: Entry name.
        status: IPOPT's return status (``Solve_Succeeded`` on success).
        success: Whether the status is a success.
        iterations: IPOPT iterations.
        solve_time: Wall time inside ``nlpsol`` [s].
        build_time: Wall time building the NLP and the solver [s].
        objective: Final cost.
        max_violation: Largest dynamics-constraint (collocation defect) violation, in the
            physical units of the state.
        states: (N + 1) x nx.
        inputs: N x nu.
        midpoints: Midpoint states, N x nx.
        timing: CasADi's per-function wall times [s] (what dominates the solve).
    """

    name: str
    status: str
    success: bool
    iterations: int
    solve_time: float
    build_time: float
    objective: float
    max_violation: float
    states: Array
    inputs: Array
    midpoints: Array
    timing: dict[str, float]


class NodeTerms:
    """Constraints and cost of one node, written on that node's own symbols."""

    def __init__(self) -> None:
        self.constraints: list[Any] = []
        self.lower: list[Array] = []
        self.upper: list[Array] = []
        self.cost: Any = 0.0

    def add(self, expr: Any, lower: Any, upper: Any) -> None:
        """Require ``lower <= expr <= upper`` (bounds broadcast to the size of ``expr``)."""
        expr = ca.vec(expr)
        size = expr.shape[0]
        self.constraints.append(expr)
        self.lower.append(np.broadcast_to(np.asarray(lower, dtype=float), (size,)).copy())
        self.upper.append(np.broadcast_to(np.asarray(upper, dtype=float), (size,)).copy())


@dataclass(frozen=True)
class NodeSpec:
    """What node ``k`` of the grid is.

    Attributes:
        signature: Nodes of equal signature share one CasADi function (their constraints
            differ only through their symbols and ``values``).
        reference: Index of another node whose state this node's terms may use (the node
            where the pushing foot landed, for instance); the node itself if none.
        values: Numbers this node's terms depend on (desired speed, ...).
    """

    signature: Hashable
    reference: int
    values: tuple[float, ...]


NodeTermsBuilder = Callable[[Hashable, Any, Any, Any, Any, Any], NodeTerms]


def assemble_problem(
    *,
    name: str,
    state_names: tuple[str, ...],
    input_names: tuple[str, ...],
    state_scale: Array,
    input_scale: Array,
    times: Array,
    rates: ca.Function,
    parameters: Array,
    state_bounds: tuple[Array, Array],
    input_bounds: tuple[Array, Array],
    nodes: Sequence[NodeSpec],
    node_terms: NodeTermsBuilder,
    metadata: dict[str, Any],
    started: float,
) -> TrajectoryProblem:
    """Assemble the NLP from its dynamics and its node terms.

    The collocation defects come from :func:`collocation_defect` mapped over the grid;
    every node's constraints and cost from ``node_terms(signature, x_k, u_k, u_{k-1},
    x_{ref}, values)``, built once per signature as a CasADi function and mapped over the
    nodes that share it. The last node gets :math:`u_{N-1}` as its input; node 0 gets
    :math:`u_0` as its previous input. ``nlpsol`` expands the result to one SX graph.

    Args:
        state_bounds: Lower and upper state bounds, (N + 1) x nx, physical units (the
            midpoint of interval k takes the bounds of node k + 1).
        input_bounds: Lower and upper input bounds, N x nu, physical units.
        started: ``time.perf_counter()`` when building began (for ``build_time``).
    """
    n = len(times) - 1
    dt = float(times[1] - times[0])
    nx, nu = len(state_names), len(input_names)
    for names in (state_names, input_names):
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate names in {names}")
    w = ca.MX.sym("w", n * (2 * nx + nu) + nx)
    body = ca.reshape(w[: n * (2 * nx + nu)], 2 * nx + nu, n)
    xs = ca.horzcat(body[:nx, :], w[n * (2 * nx + nu) :])
    x_phys = ca.diag(ca.DM(state_scale)) @ xs
    u_phys = ca.diag(ca.DM(input_scale)) @ body[nx : nx + nu, :]
    mid_phys = ca.diag(ca.DM(state_scale)) @ body[nx + nu :, :]

    defect = collocation_defect(rates, dt)
    raw = defect.map(n)(x_phys[:, :n], mid_phys, x_phys[:, 1:], u_phys, ca.DM(parameters.T))
    scale = np.concatenate([state_scale, state_scale])
    constraints: list[Any] = [ca.vec(ca.diag(ca.DM(1.0 / scale)) @ raw)]
    lbg: list[Array] = [np.zeros(n * 2 * nx)]
    ubg: list[Array] = [np.zeros(n * 2 * nx)]
    cost: Any = 0.0

    groups: dict[Hashable, list[int]] = {}
    for k, spec in enumerate(nodes):
        groups.setdefault(spec.signature, []).append(k)
    n_values = len(nodes[0].values)
    for signature, members in groups.items():
        x = ca.SX.sym("x", nx)
        u = ca.SX.sym("u", nu)
        u_prev = ca.SX.sym("u_prev", nu)
        x_ref = ca.SX.sym("x_ref", nx)
        values = ca.SX.sym("values", n_values)
        terms = node_terms(signature, x, u, u_prev, x_ref, values)
        g = ca.vertcat(*terms.constraints) if terms.constraints else ca.SX(0, 1)
        node_function = ca.Function("node", [x, u, u_prev, x_ref, values], [g, terms.cost])
        out_g, out_cost = node_function.map(len(members))(
            x_phys[:, members],
            u_phys[:, [min(k, n - 1) for k in members]],
            u_phys[:, [max(k - 1, 0) for k in members]],
            x_phys[:, [nodes[k].reference for k in members]],
            ca.DM(np.array([nodes[k].values for k in members]).T.reshape(n_values, -1)),
        )
        if g.shape[0]:
            constraints.append(ca.vec(out_g))
            lbg.append(np.tile(np.concatenate(terms.lower), len(members)))
            ubg.append(np.tile(np.concatenate(terms.upper), len(members)))
        cost = cost + ca.sum2(out_cost)

    lbw, ubw = [], []
    for k in range(n + 1):
        lbw.append(state_bounds[0][k] / state_scale)
        ubw.append(state_bounds[1][k] / state_scale)
        if k < n:
            lbw += [input_bounds[0][k] / input_scale, state_bounds[0][k + 1] / state_scale]
            ubw += [input_bounds[1][k] / input_scale, state_bounds[1][k + 1] / state_scale]
    return TrajectoryProblem(
        name=name,
        variables=w,
        objective=cost,
        constraints=ca.vertcat(*constraints),
        lbw=np.concatenate(lbw),
        ubw=np.concatenate(ubw),
        lbg=np.concatenate(lbg),
        ubg=np.concatenate(ubg),
        state_names=state_names,
        input_names=input_names,
        state_scale=state_scale,
        input_scale=input_scale,
        times=np.asarray(times, dtype=float),
        parameters=np.asarray(parameters, dtype=float),
        rates=rates,
        defect=defect,
        build_time=time.perf_counter() - started,
        metadata=metadata,
    )


def dynamics_residual(
    problem: TrajectoryProblem, states: Array, inputs: Array, midpoints: Array
) -> Array:
    """Per interval, the max-norm of the collocation defects in physical state units."""
    mapped = problem.defect.map(problem.n_intervals)
    raw = mapped(states[:-1].T, midpoints.T, states[1:].T, inputs.T, problem.parameters.T)
    return np.max(np.abs(np.asarray(raw)), axis=0)


def solve_trajectory(
    problem: TrajectoryProblem,
    initial_states: Array,
    initial_inputs: Array,
    initial_midpoints: Array | None = None,
    max_iterations: int = 1000,
    max_wall_time: float = 600.0,
    tolerance: float = 1e-6,
    print_level: int = 0,
    linear_solver: str = "mumps",
) -> TrajectorySolution:
    """Solve a built problem with IPOPT from an initial guess.

    Args:
        problem: The NLP.
        initial_states: Guess of the states, (N + 1) x nx, physical units.
        initial_inputs: Guess of the inputs, N x nu, physical units.
        initial_midpoints: Guess of the midpoint states, N x nx (default: interpolated).
        max_iterations: IPOPT's ``max_iter``.
        max_wall_time: IPOPT's ``max_wall_time`` [s] (an unreachable target can otherwise
            keep IPOPT in its restoration phase for a long time).
        tolerance: IPOPT's ``tol`` (scaled NLP error).
        print_level: IPOPT's ``print_level`` (0 silent, 5 per iteration).
        linear_solver: IPOPT's ``linear_solver``.

    Returns:
        The solution, whatever the status (check ``success``).

    Raises:
        Interrupted: The command was interrupted (:mod:`ridempc.interrupts`).
    """
    start = time.perf_counter()
    nlp: dict[str, Any] = {"x": problem.variables, "f": problem.objective, "g": problem.constraints}
    options: dict[str, Any] = {
        "expand": True,
        "print_time": False,
        "record_time": True,
        "ipopt.print_level": print_level,
        "ipopt.max_iter": max_iterations,
        "ipopt.max_wall_time": max_wall_time,
        "ipopt.tol": tolerance,
        "ipopt.constr_viol_tol": 1e-8,
        "ipopt.linear_solver": linear_solver,
        "ipopt.mu_strategy": "adaptive",
        "ipopt.sb": "yes",
    }
    solver = ca.nlpsol("trajectory", "ipopt", nlp, options)
    build_time = problem.build_time + time.perf_counter() - start
    w0 = problem.pack(initial_states, initial_inputs, initial_midpoints)
    w0 = np.clip(w0, problem.lbw, problem.ubw)
    start = time.perf_counter()
    with casadi_solve():  # an interrupt stops IPOPT and is raised again here
        result = solver(x0=w0, lbx=problem.lbw, ubx=problem.ubw, lbg=problem.lbg, ubg=problem.ubg)
    solve_time = time.perf_counter() - start
    stats = solver.stats()
    states, inputs, midpoints = problem.unpack(np.asarray(result["x"]).ravel())
    timing = {
        key[len("t_wall_") :]: float(value)
        for key, value in stats.items()
        if key.startswith("t_wall_") and isinstance(value, float)
    }
    return TrajectorySolution(
        name=problem.name,
        status=str(stats["return_status"]),
        success=bool(stats["success"]),
        iterations=int(stats["iter_count"]),
        solve_time=solve_time,
        build_time=build_time,
        objective=float(result["f"]),
        max_violation=float(np.max(dynamics_residual(problem, states, inputs, midpoints))),
        states=states,
        inputs=inputs,
        midpoints=midpoints,
        timing=timing,
    )
