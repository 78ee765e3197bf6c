"""``ridempc bench``: the MPC QP handed to other solvers is the same QP; bad input refused.

The benchmark itself (timings) is a command, not a test: ``ridempc bench --json FILE``.
"""

from __future__ import annotations

import math

import casadi
import numpy as np
import pytest
import qpsolvers

from ridempc.bench import _as_qpsolvers, _objective, _other_solvers, _solve_hpipm, _stage_layout
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


def _off_reference_qp() -> tuple:
    mpc = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.3)
    x0 = mpc.reference.sample(-1.0, 0, 1.0).states[0] + 0.01  # a little off the reference
    problem = mpc.problem(0.5, x0)
    return mpc.build_qp(problem, eps_abs=1e-7, eps_rel=1e-7), problem


@pytest.mark.skipif(not casadi.has_conic("hpipm"), reason="CasADi without HPIPM")
def test_hpipm_in_stage_layout_finds_osqps_optimum() -> None:
    qp, problem = _off_reference_qp()
    p, a = qp.matrices(problem)
    lower, upper = qp.bounds(problem)
    layout = _stage_layout(qp.horizon, qp.nx, qp.nu, qp.n_constraints)
    assert sorted(layout.columns) == list(range(qp.n_variables))  # a permutation
    assert sorted([*layout.rows, *layout.bound_rows]) == list(range(qp.n_rows))
    z, seconds = _solve_hpipm(p, a, lower, upper, layout)
    assert z is not None and seconds > 0.0
    assert np.all(a @ z >= lower - 1e-5) and np.all(a @ z <= upper + 1e-5)
    reference = qpsolvers.solve_problem(_as_qpsolvers(p, a, lower, upper), solver="osqp",
                                        eps_abs=1e-8, eps_rel=1e-8)  # fmt: skip
    assert reference.x is not None
    assert _objective(p, z) == pytest.approx(_objective(p, reference.x), rel=1e-4, abs=1e-6)


def test_every_other_solver_reports_numbers() -> None:
    qp, problem = _off_reference_qp()
    out = _other_solvers(qp, [problem])
    if casadi.has_conic("hpipm"):
        assert "hpipm (casadi)" in out
    for name, figures in out.items():
        assert "error" not in figures, (name, figures)
        assert figures["failures"] == 0, name
        assert figures["objective_gap_max"] < 1e-3, name


def test_bad_input_is_refused(capsys) -> None:
    assert main(["bench", "--pairs", "cassie-skateboard"]) == 2
    assert "cassie-skateboard" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exited:  # argparse's error, one line
        main(["bench", "--seconds", "0"])
    assert exited.value.code == 2
    assert "--seconds: 0 is out of range" in capsys.readouterr().err
    assert main(["bench", "--scenario", "no-such-scenario"]) == 2
    assert "no-such-scenario" in capsys.readouterr().err
    assert main(["bench", "--pairs", "cassie-segway", "--scenario", "push-off-0.5"]) == 2
    assert "push-off-0.5" in capsys.readouterr().err
    assert main(["bench", "--wbc-solver", "qpoases"]) == 2
    assert "whole-body QP solver 'qpoases' (valid: daqp, osqp)" in capsys.readouterr().err


def test_the_closed_loop_can_ride_on_osqp() -> None:
    """``--wbc-solver osqp``: the ride's whole-body QPs and their timing go to OSQP (the
    registry's DAQP then compared with it), and the ride stays up."""
    from ridempc.bench import bench_pair

    out = bench_pair("cassie", "segway", seconds=0.2, wbc_solver="osqp")
    assert out.ride_status == "ok" and out.wbc_ticks == 100 and out.wbc_failures == 0
    assert out.wbc_solver == "osqp" and out.wbc_solvers["osqp"]["warm_started"]
    assert out.wbc_solvers["daqp"]["failures"] == 0
    assert out.wbc_solvers["daqp"]["first_input_diff_max"] < 1e-3  # [N m]
    assert out.wbc_solve_median_ms > 0.0 and out.real_time_factor > 0.0


def test_the_wbc_is_timed_as_the_rider_runs_it() -> None:
    """The recorded whole-body QPs are solved again by a WBC with the rider's own settings
    (Cassie's springs held rigid): a default one, with passive springs, failed on 30 % of
    the Segway's ticks and was not the controller that rode."""
    from ridempc.bench import bench_pair

    out = bench_pair("cassie", "segway", seconds=0.2)
    assert out.ride_status == "ok" and out.wbc_ticks == 100
    assert out.wbc_failures == 0
    # each problem's fastest pass: never slower than the first pass, at the p99 as well
    assert 0.0 < out.wbc_solve_best_p99_ms <= out.wbc_solve_p99_ms
    assert 0.0 < out.mpc_solve_best_p99_ms <= out.mpc_solve_p99_ms
    # OSQP with the rows' classes from their bounds: the Segway's never change, same plans
    from ridempc.bench import OSQP_BOUNDS_CLASSES

    classes_by_bounds = out.solvers[OSQP_BOUNDS_CLASSES]
    assert classes_by_bounds["failures"] == 0 and classes_by_bounds["first_input_diff_max"] == 0.0
    # the closed loop's budget: its parts add up to the loop's wall time per tick
    from ridempc.bench import BUDGET_PARTS

    parts = [out.budget_ms[k] for k in BUDGET_PARTS]
    assert all(p > 0.0 for p in parts), out.budget_ms
    assert sum(parts) == pytest.approx(out.budget_ms["loop"], rel=1e-9)
    assert out.budget_ms["loop"] == pytest.approx(2.0 / out.real_time_factor, rel=1e-6)
    # the loop's own CPU time, what a loaded machine's other processes add least to
    assert math.isfinite(out.cpu_real_time_factor) and out.cpu_real_time_factor > 0.0
    assert "steady_median" in out.tick_phases_cpu_ms
    # the machine's speed of the moment, to compare benches made at different times
    assert 0.0 < out.reference_ms < 1e3  # [ms] a million additions
    from ridempc.bench import bench_table

    lines = bench_table([out]).splitlines()
    assert any(f"| {out.reference_ms:.2f} |" in line for line in lines)
    # the same QPs, to DAQP and proxqp: the same optimum (OSQP polished to its active set)
    assert {"osqp", "daqp"} <= set(out.wbc_solvers)
    for name, figures in out.wbc_solvers.items():
        assert figures["failures"] == 0, name
        assert figures["objective_gap_max"] < 1e-4, name
