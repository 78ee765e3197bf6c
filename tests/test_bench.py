"""``ridempc bench``: the MPC QP handed to other solvers is the same QP; bad input refused.

The benchmark itself (timings) is a command, not a test: ``ridempc bench --json FILE``.
"""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers

from ridempc.bench import _as_qpsolvers, _objective
from ridempc.cli import main
from ridempc.mpc.controller import LinearMpc


@pytest.mark.parametrize(
    "solver", [s for s in ("proxqp", "daqp") if s in qpsolvers.available_solvers]
)
def test_other_solvers_find_osqps_optimum(solver: str) -> None:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)
    x0 = mpc.reference.sample(-1.0, 0, 1.0).states[0] + 0.01  # a little off the reference
    problem = mpc.problem(0.5, x0)
    qp = mpc.build_qp(problem, eps_abs=1e-7, eps_rel=1e-7)
    plan = qp.solve(problem)
    assert plan.status == "solved"
    p, a = qp.matrices(problem)
    lower, upper = qp.bounds(problem)
    solution = qpsolvers.solve_problem(_as_qpsolvers(p, a, lower, upper), solver=solver)
    assert solution.found and solution.x is not None
    z = solution.x
    assert np.all(a @ z >= lower - 1e-5) and np.all(a @ z <= upper + 1e-5)
    reference = qpsolvers.solve_problem(_as_qpsolvers(p, a, lower, upper), solver="osqp",
                                        eps_abs=1e-8, eps_rel=1e-8)  # fmt: skip
    assert reference.x is not None
    best = _objective(p, reference.x)
    assert _objective(p, z) == pytest.approx(best, rel=1e-3, abs=1e-6)


def test_bad_input_is_refused(capsys) -> None:
    assert main(["bench", "--pairs", "cassie-skateboard"]) == 2
    assert "cassie-skateboard" in capsys.readouterr().err
    assert main(["bench", "--seconds", "0"]) == 2
    assert "--seconds 0" in capsys.readouterr().err
