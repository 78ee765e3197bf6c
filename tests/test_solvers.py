"""The solver registry: each kind of QP solved by its chosen solver agrees with OSQP run to
a tight tolerance; names checked; the WBC and the MPC take their solvers from it."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pytest

from ridempc.errors import UnknownNameError
from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.qp import MpcQP
from ridempc.solvers import QP_KINDS, solve_dense, solver_for
from ridempc.wbc.settings import SOLVERS, WbcSettings
from tests.helpers import osqp_tight


class _Dense(NamedTuple):
    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    l: np.ndarray  # noqa: E741 - the QP's usual name
    u: np.ndarray


def _small_dense_qp(seed: int) -> _Dense:
    """A whole-body-like QP: equality rows (dynamics), boxes, free rows (inf bounds)."""
    rng = np.random.default_rng(seed)
    n, m = 12, 10
    root = rng.normal(size=(n, n))
    p = root @ root.T + 0.1 * np.eye(n)
    a = rng.normal(size=(m, n))
    lower = np.concatenate([np.full(3, 0.5), np.full(4, -1.0), np.full(3, -np.inf)])
    upper = np.concatenate([np.full(3, 0.5), np.full(4, 1.0), np.full(3, 0.2)])
    return _Dense(p, rng.normal(size=n) * 5.0, a, lower, upper)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_wbc_solver_finds_osqps_optimum(seed: int) -> None:
    problem = _small_dense_qp(seed)
    answer = solve_dense(solver_for("wbc"), problem)
    assert answer.found and answer.x is not None and answer.seconds > 0.0
    reference = osqp_tight(problem.P, problem.q, problem.A, problem.l, problem.u)
    assert answer.x == pytest.approx(reference, abs=1e-6)
    ax = problem.A @ answer.x
    assert np.all(ax >= problem.l - 1e-9) and np.all(ax <= problem.u + 1e-9)


def test_the_mpc_solver_finds_osqps_optimum() -> None:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)
    x0 = mpc.reference.sample(-1.0, 0, 1.0).states[0] + 0.01  # a little off the reference
    problem = mpc.problem(0.5, x0)
    qp = mpc.build_qp(problem, eps_abs=1e-7, eps_rel=1e-7)
    assert isinstance(qp, MpcQP) and solver_for("mpc") == "osqp"
    plan = qp.solve(problem)
    assert plan.status == "solved"
    p, a = qp.matrices(problem)
    lower, upper = qp.bounds(problem)
    z = osqp_tight(p.toarray(), np.zeros(p.shape[0]), a.toarray(), lower, upper)
    n = (qp.horizon + 1) * qp.nx
    u0 = problem.input_reference[0] + qp._scale[n : n + qp.nu] * z[n : n + qp.nu]
    tolerance = qp._scale[n : n + qp.nu]
    assert np.max(np.abs(plan.first_input - u0) / tolerance) < 1e-3


def test_names_are_checked_and_the_controllers_ask_the_registry() -> None:
    assert solver_for("wbc") == QP_KINDS["wbc"].solver == WbcSettings().solver
    assert solver_for("wbc", "osqp") == "osqp"
    assert SOLVERS == QP_KINDS["wbc"].solvers
    for kind in QP_KINDS.values():
        assert kind.solver in kind.solvers and kind.solver not in kind.compared
    with pytest.raises(UnknownNameError, match="unknown QP kind 'lqr' \\(valid: mpc, wbc\\)"):
        solver_for("lqr")
    with pytest.raises(UnknownNameError, match="unknown mpc QP solver 'daqp' \\(valid: osqp\\)"):
        solver_for("mpc", "daqp")
    with pytest.raises(UnknownNameError, match="dense QP solver 'qpoases'"):
        solve_dense("qpoases", _small_dense_qp(0))
