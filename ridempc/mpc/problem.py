"""The MPC's problem: the time-varying linear model of eq. (17)-(18) and the cost of eq. (19).

The continuous dynamics :math:`\\dot x = f(x, u, p)` of a robot-board pair (the CasADi
``rates`` the motion library was optimised with, :mod:`ridempc.trajopt`) are linearised at
the estimated state :math:`\\hat x_0` and, per step, at the reference input
:math:`\\bar u_k` and mode :math:`p_k` of the library trajectory:

.. math::

    \\dot x \\approx f(\\hat x_0, \\bar u_k, p_k) + A^c_k (x - \\hat x_0)
                   + B^c_k (u - \\bar u_k) \\quad (17)

As in the skateboard paper (Sec. V-B), the foot lever arms, the attitudes and the board's
pose are the estimate's and are held over the horizon: every Jacobian is taken once per
solve at :math:`\\hat x_0` (only the input operating point and the contact mode follow the
schedule), so the model is linear time-varying through :math:`\\bar u_k` and :math:`p_k`
alone, and both Jacobians are built once per pair as CasADi functions. Every pair's
dynamics are affine in the inputs, :math:`f = f_0(x, p) + G(x, p)\\, u`, so
:math:`B^c_k = G(\\hat x_0, p_k)` is the paper's frozen input matrix, and
:math:`A^c_k = \\partial_x f_0 + \\partial_x (G \\bar u_k)` keeps, unlike eq. (17), how the
reference forces' moments change when the body moves over its feet (the pendulum terms).
``hold_lever_arms=True`` drops them, :math:`A^c = \\partial_x f_0(\\hat x_0, p_k)`, which is
eq. (17) exactly: a sparser QP (a third faster on the skateboard), but in closed loop on the
skateboard's 0.3 m/s push the deck roll error triples and the lateral velocity error grows
eightfold, so it is not the default.

**Discretisation** (eq. 18), zero-order hold over a step :math:`\\Delta t`, exact for the
linear model, from the exponential of the augmented matrix (Van Loan), whose top block
row :func:`zero_order_hold` computes:

.. math::

    \\exp\\left(\\Delta t \\begin{bmatrix} A^c_k & B^c_k & f_k \\\\ 0 & 0 & 0 \\\\ 0 & 0 & 0
    \\end{bmatrix}\\right) = \\begin{bmatrix} A_k & B_k & g_k \\\\ 0 & I & 0 \\\\ 0 & 0 & 1
    \\end{bmatrix}, \\qquad
    x_{k+1} = A_k x_k + B_k u_k + c_k, \\quad c_k = \\hat x_0 + g_k - A_k \\hat x_0 - B_k \\bar u_k

Zero-order hold is what the controller does with the plan (it applies :math:`u_0` for a
whole step), and it stays exact for the boards' fast modes: the Hovershoes' and the
Segway's closed-loop platform pitch has poles near -80 and -140 rad/s, so that
:math:`\\lambda \\Delta t \\approx -4.7` at 30 Hz, outside the stability region of one
explicit RK4 step (about -2.8); an RK-consistent discretisation would need sub-steps and
would still be approximate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.mpc.buffered import BufferedFunction
from ridempc.mpc.codegen import compiled
from ridempc.mpc.discretisation import zero_order_hold
from ridempc.trajopt.schedule import Contact

__all__ = [
    "MPC_STEP",
    "LinearModel",
    "LinearisedDynamics",
    "MpcProblem",
    "build_linear_model",
    "linearize",
]

Array = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
MPC_STEP: float = 1.0 / 30.0  # [s], the paper's 30 Hz


class LinearisedDynamics(NamedTuple):
    """Discrete dynamics :math:`x_{k+1} = A_k x_k + B_k u_k + c_k` over a horizon (eq. 18).

    Attributes:
        A: N x nx x nx.
        B: N x nx x nu.
        c: N x nx, in the state's units.
    """

    A: Array
    B: Array
    c: Array


@dataclass(frozen=True)
class LinearModel:
    """The Jacobians of a pair's ``rates``, built once per pair.

    Attributes:
        rates: :math:`f(x, u, p)`.
        jacobians: CasADi function ``(x, u, p) -> (f, A^c, B^c)`` (module docstring).
        nx: State size.
        nu: Input size.
        n_parameters: Mode-parameter size.
        state_pattern: Structural non-zeros of the discrete :math:`A_k` (nx x nx), for
            every state, input and mode: the states reachable through the continuous
            :math:`A^c` (the exponential fills in what a chain of couplings reaches).
        input_pattern: Structural non-zeros of the discrete :math:`B_k` (nx x nu).
    """

    rates: ca.Function
    jacobians: ca.Function
    nx: int
    nu: int
    n_parameters: int
    state_pattern: BoolArray
    input_pattern: BoolArray
    _mapped: dict[int, _MappedJacobians] = field(default_factory=dict, repr=False, compare=False)

    def evaluate(self, x0: Array, u_ref: Array, p_k: Array) -> tuple[Array, Array, Array]:
        """:attr:`jacobians` at :math:`(\\hat x_0, \\bar u_k, p_k)` for every step, in one
        call of a mapped function built once per horizon (compiled to C and cached,
        :func:`~ridempc.mpc.codegen.compiled`).

        Returns:
            :math:`f_k` (N x nx), :math:`A^c_k` (N x nx x nx), :math:`B^c_k` (N x nx x nu).
        """
        horizon = len(u_ref)
        if horizon not in self._mapped:
            mapped = compiled(self.jacobians.map(horizon))  # C where a compiler is found
            self._mapped[horizon] = _MappedJacobians(mapped, horizon)
        return self._mapped[horizon](x0, u_ref, p_k)


class _MappedJacobians:
    """A mapped Jacobian function evaluated into NumPy buffers
    (:class:`~ridempc.mpc.buffered.BufferedFunction`), its sparse outputs scattered into
    dense stacks: converting CasADi matrices to NumPy costs more than evaluating them."""

    def __init__(self, function: ca.Function, horizon: int) -> None:
        self.function, self.horizon = function, horizon
        self.buffered = BufferedFunction(function)
        self.scatter = []
        for i in (1, 2):  # columns j + k n of step k, nonzeros in column-major order
            rows, cols = (
                np.array(v, dtype=np.int64) for v in function.sparsity_out(i).get_triplet()
            )
            n = function.size2_out(i) // horizon
            self.scatter.append((cols // n, rows, cols % n, n))

    def __call__(self, x0: Array, u_ref: Array, p_k: Array) -> tuple[Array, Array, Array]:
        results = self.buffered.nonzeros(np.tile(x0, self.horizon), u_ref.ravel(), p_k.ravel())
        nx = len(x0)
        rates = results[0].reshape(self.horizon, nx).copy()
        dense = []
        for (k, i, j, n), values in zip(self.scatter, results[1:], strict=True):
            out = np.zeros((self.horizon, nx, n))
            out[k, i, j] = values
            dense.append(out)
        return rates, dense[0], dense[1]


def _reachability(continuous: BoolArray) -> BoolArray:
    """Boolean closure of :math:`I + A`: where :math:`\\exp(A t)` can be non-zero."""
    n = continuous.shape[0]
    reach = continuous | np.eye(n, dtype=bool)
    while True:
        grown = (reach.astype(np.int64) @ reach.astype(np.int64)) > 0
        if np.array_equal(grown, reach):
            return reach
        reach = grown


def build_linear_model(rates: ca.Function, hold_lever_arms: bool = False) -> LinearModel:
    """Differentiate a pair's dynamics once (CasADi SX, exact Jacobians).

    Args:
        rates: :math:`\\dot x = f(x, u, p)` with inputs ``(x, u, p)`` and one output.
        hold_lever_arms: Drop the state derivatives of the input coupling,
            :math:`A^c = \\partial_x f(x, 0, p)` (the paper's eq. 17); else
            :math:`A^c = \\partial_x f(x, \\bar u, p)`.

    Returns:
        The Jacobian function and the structural sparsity of the discrete model.
    """
    nx, nu, n_p = rates.size1_in(0), rates.size1_in(1), rates.size1_in(2)
    x, u, p = ca.SX.sym("x", nx), ca.SX.sym("u", nu), ca.SX.sym("p", n_p)
    f = rates(x, u, p)
    drift = rates(x, ca.DM.zeros(nu), p) if hold_lever_arms else f
    jac_x, jac_u = ca.jacobian(drift, x), ca.jacobian(f, u)
    jacobians = ca.Function("rates_jacobians", [x, u, p], [f, jac_x, jac_u])
    continuous_a = np.array(ca.DM(jac_x.sparsity(), 1)) != 0
    continuous_b = np.array(ca.DM(jac_u.sparsity(), 1)) != 0
    reach = _reachability(continuous_a)
    input_pattern = (reach.astype(np.int64) @ continuous_b.astype(np.int64)) > 0
    return LinearModel(
        rates=rates,
        jacobians=jacobians,
        nx=nx,
        nu=nu,
        n_parameters=n_p,
        state_pattern=reach,
        input_pattern=input_pattern,
    )


@lru_cache(maxsize=8)
def _cached_model(rates: ca.Function) -> LinearModel:
    return build_linear_model(rates)


def linearize(
    rates: ca.Function | LinearModel,
    x0: Array,
    u_ref: Array,
    p_k: Array,
    dt: float = MPC_STEP,
    drift: Array | None = None,
) -> LinearisedDynamics:
    """Linearise the dynamics at the estimate and discretise them with a zero-order hold.

    Args:
        rates: The pair's :math:`f(x, u, p)`, or its :class:`LinearModel` (pass the model in
            a loop: a bare ``rates`` is differentiated once and cached by identity).
        x0: Estimated state :math:`\\hat x_0` (nx), the pair's state layout.
        u_ref: Reference inputs :math:`\\bar u_k`, N x nu.
        p_k: Mode parameters :math:`p_k`, N x n_p.
        dt: Step :math:`\\Delta t` [s].
        drift: A constant term :math:`\\Delta f` (nx) added to the rates over the whole
            horizon, :math:`\\dot x = f + \\Delta f` (an estimated disturbance, in the
            states' rates' units), discretised with them; None: none.

    Returns:
        :math:`A_k, B_k, c_k` of eq. (18) (see the module docstring).
    """
    model = rates if isinstance(rates, LinearModel) else _cached_model(rates)
    x0 = np.asarray(x0, dtype=float).ravel()
    u_ref = np.atleast_2d(np.asarray(u_ref, dtype=float))
    p_k = np.asarray(p_k, dtype=float).reshape(len(u_ref), -1)
    nx, nu = model.nx, model.nu
    if x0.shape != (nx,) or u_ref.shape[1] != nu or p_k.shape[1] != model.n_parameters:
        raise ValueError(
            f"linearize: x0 {x0.shape}, u_ref {u_ref.shape}, p_k {p_k.shape} do not match "
            f"nx={nx}, nu={nu}, n_p={model.n_parameters}"
        )
    if not dt > 0.0:
        raise ValueError(f"linearize: dt must be positive, got {dt}")
    rates_0, a_c, b_c = model.evaluate(x0, u_ref, p_k)
    if drift is not None:
        rates_0 = rates_0 + drift
    a_d, phi = zero_order_hold(a_c, dt)
    b_d = phi @ b_c
    g_d = np.einsum("kij,kj->ki", phi, rates_0)
    c_d = x0 + g_d - a_d @ x0 - np.einsum("kij,kj->ki", b_d, u_ref)
    return LinearisedDynamics(a_d, b_d, c_d)


def _shaped(name: str, value: Array, shape: tuple[int, ...]) -> Array:
    array = np.asarray(value, dtype=float)
    if array.shape != shape:
        raise ValueError(f"MpcProblem: {name} has shape {array.shape}, expected {shape}")
    return array


@dataclass(frozen=True)
class MpcProblem:
    """One MPC problem, eq. (18)-(19) with the contact constraints (checked on construction).

    .. math::

        \\min_{x, u} \\sum_{k=1}^{N} \\|x_k - x^{ref}_k\\|^2_{Q_k}
                   + \\sum_{k=0}^{N-1} \\|u_k - u^{ref}_k\\|^2_R \\quad (19)

    subject to :math:`x_0 = \\hat x_0`, :math:`x_{k+1} = A_k x_k + B_k u_k + c_k`,
    :math:`u^{lo}_k \\le u_k \\le u^{hi}_k` and :math:`g^{lo}_k \\le G_k u_k \\le g^{hi}_k`
    (friction pyramids, see :mod:`ridempc.mpc.friction`), with :math:`Q_N` the terminal
    weight. Eq. (19) penalises :math:`\\|u_k\\|_R`; here the inputs are drawn to the library's
    (:math:`u^{ref} = 0` gives the paper's form).

    Attributes:
        initial_state: :math:`\\hat x_0` (nx).
        A: N x nx x nx.
        B: N x nx x nu.
        c: N x nx.
        state_reference: :math:`x^{ref}_0 \\dots x^{ref}_N`, (N + 1) x nx.
        input_reference: :math:`u^{ref}_k`, N x nu.
        state_weights: Diagonal of :math:`Q` (nx), in [1 / state unit^2].
        input_weights: Diagonal of :math:`R` (nu), in [1 / input unit^2], or one per step
            (N x nu).
        input_lower: :math:`u^{lo}_k`, N x nu (-inf: unbounded).
        input_upper: :math:`u^{hi}_k`, N x nu (inf: unbounded).
        constraint_matrix: :math:`G_k`, N x m x nu.
        constraint_lower: :math:`g^{lo}_k`, N x m.
        constraint_upper: :math:`g^{hi}_k`, N x m.
        dt: Step :math:`\\Delta t` [s].
        terminal_weights: Diagonal of :math:`Q_N` (nx); default :math:`Q`.
        contacts: Per step, where each contact is (the schedule the bounds come from);
            empty when not known.
    """

    initial_state: Array
    A: Array
    B: Array
    c: Array
    state_reference: Array
    input_reference: Array
    state_weights: Array
    input_weights: Array
    input_lower: Array
    input_upper: Array
    constraint_matrix: Array
    constraint_lower: Array
    constraint_upper: Array
    dt: float = MPC_STEP
    terminal_weights: Array | None = None
    contacts: tuple[tuple[Contact, ...], ...] = ()

    def __post_init__(self) -> None:
        a = np.asarray(self.A, dtype=float)
        if a.ndim != 3 or a.shape[1] != a.shape[2] or a.shape[0] < 1:
            raise ValueError(f"MpcProblem: A has shape {a.shape}, expected N x nx x nx")
        n, nx = a.shape[0], a.shape[1]
        b = np.asarray(self.B, dtype=float)
        if b.ndim != 3 or b.shape[:2] != (n, nx):
            raise ValueError(f"MpcProblem: B has shape {b.shape}, expected {n} x {nx} x nu")
        nu = b.shape[2]
        g = np.asarray(self.constraint_matrix, dtype=float)
        if g.ndim != 3 or g.shape[0] != n or g.shape[2] != nu:
            raise ValueError(
                f"MpcProblem: constraint_matrix has shape {g.shape}, expected {n} x m x {nu}"
            )
        m = g.shape[1]
        terminal = self.state_weights if self.terminal_weights is None else self.terminal_weights
        checked = {
            "initial_state": _shaped("initial_state", self.initial_state, (nx,)),
            "A": a,
            "B": b,
            "c": _shaped("c", self.c, (n, nx)),
            "state_reference": _shaped("state_reference", self.state_reference, (n + 1, nx)),
            "input_reference": _shaped("input_reference", self.input_reference, (n, nu)),
            "state_weights": _shaped("state_weights", self.state_weights, (nx,)),
            "input_weights": _shaped(
                "input_weights",
                self.input_weights,
                (n, nu) if np.ndim(self.input_weights) == 2 else (nu,),
            ),
            "terminal_weights": _shaped("terminal_weights", terminal, (nx,)),
            "input_lower": _shaped("input_lower", self.input_lower, (n, nu)),
            "input_upper": _shaped("input_upper", self.input_upper, (n, nu)),
            "constraint_matrix": g,
            "constraint_lower": _shaped("constraint_lower", self.constraint_lower, (n, m)),
            "constraint_upper": _shaped("constraint_upper", self.constraint_upper, (n, m)),
        }
        bounds = ("input_lower", "input_upper", "constraint_lower", "constraint_upper")
        for name, value in checked.items():
            # a sum is NaN or infinite when an entry is: one reduction, not an array of flags
            if name not in bounds and not math.isfinite(value.sum()):
                raise ValueError(f"MpcProblem: {name} holds NaN or infinite values")
            if name in bounds and np.isnan(value).any():
                raise ValueError(f"MpcProblem: {name} holds NaN")
            object.__setattr__(self, name, value)
        for name in ("state_weights", "input_weights", "terminal_weights"):
            if checked[name].min() < 0.0:
                raise ValueError(f"MpcProblem: {name} must be non-negative")
        for low, high in (("input_lower", "input_upper"), ("constraint_lower", "constraint_upper")):
            above = checked[low] > checked[high]
            if above.any():
                k, i = np.argwhere(above)[0]
                raise ValueError(
                    f"MpcProblem: {low}[{k}, {i}] = {checked[low][k, i]:g} is above "
                    f"{high}[{k}, {i}] = {checked[high][k, i]:g}"
                )
        if not (np.isfinite(self.dt) and self.dt > 0.0):
            raise ValueError(f"MpcProblem: dt must be positive, got {self.dt}")

    @property
    def horizon(self) -> int:
        """N, the number of steps."""
        return int(self.A.shape[0])

    @property
    def nx(self) -> int:
        return int(self.A.shape[1])

    @property
    def nu(self) -> int:
        return int(self.B.shape[2])

    @property
    def n_constraints(self) -> int:
        """m, the polyhedral input constraints per step."""
        return int(self.constraint_matrix.shape[1])

    @property
    def final_weights(self) -> Array:
        """:math:`Q_N`."""
        assert self.terminal_weights is not None  # set by __post_init__
        return self.terminal_weights
