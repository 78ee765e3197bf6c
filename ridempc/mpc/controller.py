"""The 30 Hz linear MPC of a robot-board pair: reference -> linearisation -> QP -> plan.

Built once per pair and manoeuvre (:meth:`LinearMpc.from_library`): the pair's dynamics
and their Jacobians (:func:`~ridempc.mpc.problem.build_linear_model`), the library
reference (:func:`~ridempc.mpc.reference.select_reference`), the weights
(:func:`~ridempc.mpc.weights.bryson_weights`) and the QP with its fixed sparsity
(:class:`~ridempc.mpc.qp.MpcQP`). Each tick, :meth:`LinearMpc.update` samples the
reference over the horizon, linearises at the estimated state, builds the friction
pyramids with the surface rotations of that state, and solves:

.. code-block:: python

    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.5)
    plan = mpc.update(t, x0)   # t [s] since the manoeuvre began, x0 in the pair's layout
    forces_and_rates = plan.first_input
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.canonical import board_state_columns
from ridempc.errors import ConfigError
from ridempc.mpc.friction import force_bounds, friction_pyramids, pyramid_pattern
from ridempc.mpc.pairs import MpcPair, load_mpc_pair, surface_rotations
from ridempc.mpc.plan import Plan
from ridempc.mpc.problem import MPC_STEP, LinearModel, MpcProblem, build_linear_model, linearize
from ridempc.mpc.push_weights import with_push_weights
from ridempc.mpc.qp import MpcQP, QPStructure
from ridempc.mpc.reference import MotionReference, select_reference, steady_riding
from ridempc.mpc.statics import StaticShift, static_shift
from ridempc.mpc.weights import bryson_weights
from ridempc.solvers import solver_for
from ridempc.trajopt.schedule import Contact

__all__ = ["LinearMpc", "MpcSettings"]

Array = NDArray[np.float64]
_QP_BACKENDS: dict[str, type[MpcQP]] = {"osqp": MpcQP}  # the MPC's QP, by solver name


@dataclass(frozen=True)
class MpcSettings:
    """Settings of the MPC.

    Attributes:
        horizon: N, steps [-].
        dt: Step [s] (30 Hz in the paper).
        terminal_factor: :math:`Q_N = ` this :math:`\\times Q` [-]; None: the pair's
            (:attr:`~ridempc.mpc.pairs.MpcPair.terminal_factor`).
        weights: Overrides of :math:`Q` and :math:`R` by state or input name.
        osqp: Overrides of the QP's OSQP settings.
        fixed_inputs: Inputs held at a value over the whole horizon, by name (an input the
            rider cannot realise, such as the Segway's knee bar when nothing pushes it, must
            not be planned with).
    """

    horizon: int = 12
    dt: float = MPC_STEP
    terminal_factor: float | None = None
    weights: Mapping[str, float] = field(default_factory=dict)
    osqp: Mapping[str, float | int | bool] = field(default_factory=dict)
    fixed_inputs: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.horizon < 1:
            raise ConfigError(f"MPC horizon must be at least 1 step, got {self.horizon}")
        if not self.dt > 0.0:
            raise ConfigError(f"MPC step must be positive, got {self.dt} s")
        if self.terminal_factor is not None and not self.terminal_factor >= 0.0:
            raise ConfigError(
                f"MPC terminal factor must be non-negative, got {self.terminal_factor}"
            )


def _riding(pair: MpcPair, reference: MotionReference, rates: ca.Function) -> MotionReference:
    """``reference`` ridden on after its end (:func:`~ridempc.mpc.reference.steady_riding`),
    settling as the pair says (``MpcPair.settle``)."""
    steady = steady_riding(reference, rates)
    return steady if pair.settle is None else pair.settle(steady)


def _tolerance(weights: Array) -> Array:
    """Bryson's tolerances back from the weights (the QP's scales); 1 for a zero weight."""
    return np.where(weights > 0.0, 1.0 / np.sqrt(np.where(weights > 0.0, weights, 1.0)), 1.0)


class LinearMpc:
    """The MPC of one pair tracking one reference (see the module docstring).

    Attributes:
        pair: The pair's surfaces and limits.
        reference: The trajectory tracked.
        model: The pair's Jacobians.
        settings: Horizon, step, weights.
        state_weights: Diagonal of :math:`Q`.
        input_weights: Diagonal of :math:`R`.
        qp: The QP (built by the first :meth:`update`).
    """

    def __init__(
        self,
        pair: MpcPair,
        reference: MotionReference,
        model: LinearModel,
        settings: MpcSettings | None = None,
    ) -> None:
        if reference.contact_names != pair.contacts:
            raise ConfigError(
                f"reference '{reference.name}' has contacts {reference.contact_names}, the "
                f"pair {pair.pair.name} {pair.contacts}"
            )
        self.pair = pair
        self.reference = reference
        self.model = model
        self.settings = settings or MpcSettings()
        self.state_weights, self.input_weights = bryson_weights(
            reference.state_names,
            reference.input_names,
            pair.weight / len(pair.contacts),
            self.settings.weights,
            base=pair.base,
            board_states=pair.board_states,
        )
        self._fixed = self._fixed_indices(self.settings.fixed_inputs)
        self.structure = QPStructure(
            model.state_pattern,
            model.input_pattern,
            pyramid_pattern(reference.force_index, model.nu, pair.tipping),
        )
        self.qp: MpcQP | None = None
        self._shift: tuple[bytes, StaticShift] | None = None  # the last static shift, by key
        for horizon in (self.settings.horizon, 1):  # the problems' and the static shift's
            model.prepare(horizon)  # compiled before the first tick, as are the surfaces:
        surface_rotations(pair, reference.states[0])

    @property
    def terminal_factor(self) -> float:
        """:math:`Q_N / Q` [-], the settings' or else the pair's."""
        factor = self.settings.terminal_factor
        return self.pair.terminal_factor if factor is None else factor

    def _fixed_indices(self, fixed: Mapping[str, float]) -> list[tuple[int, float]]:
        names = list(self.reference.input_names)
        unknown = [n for n in fixed if n not in names]
        if unknown:
            raise ConfigError(
                f"MPC fixed input '{unknown[0]}' is not an input (valid: {', '.join(names)})"
            )
        return [(names.index(n), float(v)) for n, v in fixed.items()]

    def fix_inputs(self, values: Mapping[str, float]) -> None:
        """Hold more inputs, by name, at a value over the horizon (as ``fixed_inputs``)."""
        fixed = {**self.settings.fixed_inputs, **values}
        self._fixed = self._fixed_indices(fixed)
        self.settings = replace(self.settings, fixed_inputs=fixed)

    def steers(self) -> bool:
        """Whether an input that is not held drives a board's yaw rate directly
        (:math:`\\partial \\dot x / \\partial u \\ne 0` at the reference's start on a board
        state whose quantity is ``yaw_rate``, :attr:`~ridempc.mpc.pairs.MpcPair.
        board_states`): a Hovershoe turns under the feet's yaw torque, a Segway only by its
        knee bar, which a pinned bar cannot."""
        columns = board_state_columns(self.reference.state_names, self.pair.board_states)
        rows = [i for state, i in columns.items() if state.quantity == "yaw_rate"]
        free = [
            i
            for i, n in enumerate(self.reference.input_names)
            if n not in self.settings.fixed_inputs
        ]
        if not rows or not free:
            return False
        _, _, jac_u = self.model.jacobians(
            self.reference.states[0], self.reference.inputs[0], self.reference.parameters[0]
        )
        return bool(np.any(np.abs(np.asarray(jac_u)[np.ix_(rows, free)]) > 1e-9))

    @classmethod
    def from_library(
        cls,
        robot: str,
        board: str,
        kind: str,
        target: float,
        settings: MpcSettings | None = None,
        folder: Path | None = None,
    ) -> LinearMpc:
        """The MPC of ``robot`` on ``board`` tracking the library's ``kind`` at ``target``.

        Raises:
            UnknownNameError: No MPC for that pair.
            ConfigError: The library is missing, corrupt, or has no such kind.
        """
        pair = load_mpc_pair(robot, board)
        reference = select_reference(robot, board, kind, target, folder=folder)
        rates = pair.pair.rates(reference.metadata)
        return cls(pair, _riding(pair, reference, rates), build_linear_model(rates), settings)

    def retarget(self, kind: str, target: float, folder: Path | None = None) -> None:
        """Track another library trajectory of the same pair, keeping the Jacobians and the
        QP (its pattern depends on the pair only); times restart at its beginning.

        Raises:
            ConfigError: As :meth:`from_library`, or the entry's contacts differ.
        """
        pair = self.pair.pair
        reference = select_reference(pair.robot, pair.board, kind, target, folder=folder)
        if reference.contact_names != self.reference.contact_names:
            raise ConfigError(
                f"reference '{reference.name}' has contacts {reference.contact_names}, "
                f"expected {self.reference.contact_names}"
            )
        self.reference = _riding(self.pair, reference, self.model.rates)

    def problem(self, t: float, x0: Array, drift: Array | None = None) -> MpcProblem:
        """The MPC problem at time ``t`` [s] (since the reference's start) from ``x0``,
        with ``drift`` (nx), an estimated disturbance added to the model's rates over the
        horizon (:func:`~ridempc.mpc.problem.linearize`), if given."""
        s = self.settings
        x0 = np.asarray(x0, dtype=float).ravel()
        window = self.reference.sample(t, s.horizon, s.dt)
        dynamics = linearize(self.model, x0, window.inputs, window.parameters, s.dt, drift)
        surfaces = surface_rotations(self.pair, x0)
        index = self.reference.force_index
        g, g_lo, g_hi = friction_pyramids(
            index,
            self.model.nu,
            window.contacts,
            surfaces,
            self.reference.friction,
            self.pair.max_force,
            self.reference.min_board_share * self.pair.weight / len(index),
            self.pair.pyramid,
            self.pair.tipping,
        )
        u_lo, u_hi = force_bounds(index, window.contacts, self.pair.input_limits)
        for i, value in self._fixed:
            u_lo[:, i] = u_hi[:, i] = value
        problem = MpcProblem(
            initial_state=x0,
            A=dynamics.A,
            B=dynamics.B,
            c=dynamics.c,
            state_reference=window.states,
            input_reference=window.inputs,
            state_weights=self.state_weights,
            input_weights=self.input_weights,
            input_lower=u_lo,
            input_upper=u_hi,
            constraint_matrix=g,
            constraint_lower=g_lo,
            constraint_upper=g_hi,
            dt=s.dt,
            terminal_weights=self.terminal_factor * self.state_weights,
            contacts=window.contacts,
        )
        pair = self.pair
        return with_push_weights(
            problem,
            self.reference,
            t,
            pair.push_tolerances,
            self.terminal_factor,
            pair.push_max_target,
        )

    def static_shift(self, t: float, changed: int, rider_states: Sequence[int]) -> StaticShift:
        """How the reference at time ``t`` [s] moves, per unit change of state ``changed``,
        to stay in balance (:func:`~ridempc.mpc.statics.static_shift`): the rider's pose
        among ``rider_states`` (those no input drives) and the standing feet's forces."""
        window = self.reference.sample(t, 1, self.settings.dt)
        standing = [c is not Contact.SWING for c in window.contacts[0]]
        # Riding steadily the reference holds still, and so does its shift: kept by key.
        key = (
            b"".join(
                np.ascontiguousarray(a).tobytes()
                for a in (window.states[0], window.inputs[0], window.parameters[0], standing)
            )
            + repr((changed, tuple(rider_states))).encode()
        )
        if self._shift is not None and self._shift[0] == key:
            return self._shift[1]
        _, a_c, b_c = self.model.evaluate(window.states[0], window.inputs, window.parameters)
        forces = self.reference.force_index[np.asarray(standing)].ravel()
        poses = [i for i in rider_states if not np.any(b_c[0][i])]
        shift = static_shift(
            a_c[0], b_c[0], changed, poses, forces, self.state_weights, self.input_weights
        )
        self._shift = (key, shift)
        return shift

    def build_qp(self, problem: MpcProblem, **osqp: float | int | bool) -> MpcQP:
        """A QP for this MPC's problems on the registry's solver
        (:data:`~ridempc.solvers.QP_KINDS`, OSQP): the pair's fixed pattern, scaled by the
        weights' tolerances, OSQP set up with ``settings.osqp`` and ``osqp`` over the
        defaults."""
        return _QP_BACKENDS[solver_for("mpc")](
            problem,
            self.structure,
            state_scale=_tolerance(self.state_weights),
            input_scale=_tolerance(self.input_weights),
            **{**dict(self.settings.osqp), **osqp},
        )

    def update(self, t: float, x0: Array) -> Plan:
        """One MPC tick: the plan from the estimated state ``x0`` at time ``t`` [s].

        The first call builds the QP; later calls write new values into it.
        """
        problem = self.problem(t, x0)
        if self.qp is None:
            self.qp = self.build_qp(problem)
        return self.qp.solve(problem)
