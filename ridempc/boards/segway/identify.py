"""Identify the Segway's reduced model (:mod:`ridempc.boards.segway.reduced`) from experiments.

The physical board (MuJoCo, with its firmware) carries a dead weight of its rider's mass; the
rider's pitch torque and knee torque are scripted (:mod:`ridempc.boards.segway.experiments`).
Four trials of random steps are fitted, three held out: one more of random steps, one of
sines and one of a sustained lean to about 3.5 m/s (kinds of input never fitted). The fit
is least squares on the equations:

.. math::

    \\ddot\\theta = a_1 \\theta + a_2 \\dot\\theta + a_3 v + b_1 u_\\theta, \\quad
    \\dot v = a_4 \\theta + a_5 v + a_6 \\dot\\theta + b_2 u_\\theta, \\quad
    \\ddot\\psi = a_7 \\delta + a_8 \\dot\\psi

with derivatives by central differences of the recorded rates, from which
:math:`J_\\theta = 1 / b_1`, :math:`c_1 = -a_1 J_\\theta`, :math:`c_4 = a_4 m`, ...,
:math:`\\tau_{turn} = -1 / a_8`, :math:`k_{turn} = a_7 \\tau_{turn}`. Each held-out trial is
then predicted by integrating the reduced model from its first sample with its recorded
inputs, and scored by R^2 and the RMSE over the signal's range (NRMSE).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from pydantic import ValidationError

from ridempc.boards.board import Board
from ridempc.boards.identification import (
    IdentificationFailed,
    IdentificationResult,
    nrmse,
    r_squared,
)
from ridempc.boards.segway.experiments import Trial, piecewise, random_steps, run_trial, sine
from ridempc.boards.segway.parameters import SegwayParameters, SegwayReducedParameters
from ridempc.boards.segway.reduced import simulate_segway

__all__ = ["fit_reduced", "identify", "score_trial"]

Array = NDArray[np.float64]

DURATION: float = 6.0  # [s] per trial
PITCH_TORQUE: float = 6.0  # [N m] amplitude of the rider's pitch torque
KNEE_TORQUE: float = 8.0  # [N m] amplitude of the knee torque
SETTLE: float = 0.5  # [s] first inputs at this time; samples before are not fitted
MAX_CONDITION: float = 1e7
MAX_NRMSE: float = 0.1  # held-out error beyond which the model is refused
SIGNALS: tuple[str, ...] = ("theta", "speed", "yaw_rate")

UNITS: dict[str, str] = {
    "pitch_inertia": "kg m^2",
    "c1": "N m / rad",
    "c2": "N m s / rad",
    "c3": "N m s / m",
    "c4": "N / rad",
    "c5": "N s / m",
    "c6": "N s / rad",
    "c7": "N / (N m)",
    "mass": "kg",
    "k_turn": "(rad/s) / rad",
    "tau_turn": "s",
}


def _lstsq(rows: list[Array], targets: list[Array], what: str) -> Array:
    a, b = np.vstack(rows), np.concatenate(targets)
    condition = float(np.linalg.cond(a))
    if not np.isfinite(condition) or condition > MAX_CONDITION:
        raise IdentificationFailed(f"{what}: ill-conditioned regression (cond {condition:.3g})")
    coefficients = np.linalg.lstsq(a, b, rcond=None)[0]
    return np.asarray(coefficients, dtype=float)


def fit_reduced(trials: Sequence[Trial], mass: float, full: bool = True) -> SegwayReducedParameters:
    """Least-squares fit of the reduced model's parameters on some trials.

    Args:
        trials: Recorded experiments.
        mass: Board and rider mass :math:`m` [kg].
        full: Fit the speed equation's pitch-rate and lean terms (:math:`c_6, c_7`); False
            fits the hovershoe paper's form :math:`m \\dot v = c_4 \\theta + c_5 v`.

    Raises:
        IdentificationFailed: Ill-conditioned regression or non-physical parameters.
    """
    pitch_rows, pitch_y, speed_rows, speed_y, yaw_rows, yaw_y = [], [], [], [], [], []
    for trial in trials:
        keep = trial.time >= SETTLE
        dt = trial.dt
        theta, rate, speed = trial.theta[keep], trial.theta_rate[keep], trial.speed[keep]
        u, knee, yaw_rate = trial.u_theta[keep], trial.knee_bar[keep], trial.yaw_rate[keep]
        pitch_rows.append(np.column_stack([theta, rate, speed, u]))
        pitch_y.append(np.gradient(rate, dt))
        speed_rows.append(np.column_stack([theta, speed, rate, u] if full else [theta, speed]))
        speed_y.append(np.gradient(speed, dt))
        yaw_rows.append(np.column_stack([knee, yaw_rate]))
        yaw_y.append(np.gradient(yaw_rate, dt))
    a1, a2, a3, b1 = _lstsq(pitch_rows, pitch_y, "pitch")
    speed_coefficients = _lstsq(speed_rows, speed_y, "speed")
    a4, a5 = speed_coefficients[:2]
    a6, b2 = speed_coefficients[2:] if full else (0.0, 0.0)
    a7, a8 = _lstsq(yaw_rows, yaw_y, "yaw rate")
    if b1 <= 0.0 or a8 >= 0.0:
        raise IdentificationFailed(
            f"non-physical fit: pitch input gain {b1:.3g} (must be > 0), "
            f"yaw-rate pole {a8:.3g} (must be < 0)"
        )
    inertia = 1.0 / b1
    tau = -1.0 / a8
    try:
        return SegwayReducedParameters(
            pitch_inertia=inertia,
            c1=-a1 * inertia,
            c2=-a2 * inertia,
            c3=-a3 * inertia,
            c4=a4 * mass,
            c5=a5 * mass,
            c6=a6 * mass,
            c7=-b2 * mass,
            mass=mass,
            k_turn=a7 * tau,
            tau_turn=tau,
        )
    except ValidationError as exc:
        raise IdentificationFailed(f"non-physical fit: {exc.errors()[0]['msg']}") from exc


def _measured(trial: Trial) -> Array:
    return np.column_stack(
        [trial.x, trial.y, trial.psi, trial.theta, trial.theta_rate, trial.speed, trial.yaw_rate]
    )


def score_trial(params: SegwayReducedParameters, trial: Trial) -> dict[str, float]:
    """Predict a trial with the reduced model from its first sample and recorded inputs.

    Returns:
        ``<signal>_r2`` and ``<signal>_nrmse`` (RMSE over the signal's range) for the pitch,
        speed and yaw rate, and ``position_nrmse`` (RMSE of the position over the path's
        extent).
    """
    measured = _measured(trial)
    controls = np.column_stack([trial.u_theta, trial.knee_bar])
    predicted = simulate_segway(params, measured[0], controls, trial.dt)
    scores: dict[str, float] = {}
    for name, column in zip(SIGNALS, (3, 5, 6), strict=True):
        scores[f"{name}_r2"] = r_squared(measured[:, column], predicted[:, column])
        scores[f"{name}_nrmse"] = nrmse(measured[:, column], predicted[:, column])
    miss = np.hypot(predicted[:, 0] - measured[:, 0], predicted[:, 1] - measured[:, 1])
    extent = max(np.ptp(measured[:, 0]), np.ptp(measured[:, 1]))
    scores["position_nrmse"] = float(np.sqrt(np.mean(miss**2)) / extent)
    return scores


def _worst(scores: Sequence[dict[str, float]]) -> dict[str, float]:
    return {key: (min if key.endswith("_r2") else max)(s[key] for s in scores) for key in scores[0]}


def _trials(board: Board, mass: float) -> tuple[list[Trial], list[Trial]]:
    fit = [
        run_trial(
            board,
            mass,
            DURATION,
            random_steps(2 * i, DURATION, PITCH_TORQUE, (0.3, 1.0)),
            random_steps(2 * i + 1, DURATION, KNEE_TORQUE, (0.4, 1.2)),
        )
        for i in range(4)
    ]
    held_out = [
        run_trial(
            board,
            mass,
            DURATION,
            random_steps(100, DURATION, PITCH_TORQUE, (0.3, 1.0)),
            random_steps(101, DURATION, KNEE_TORQUE, (0.4, 1.2)),
        ),
        run_trial(board, mass, DURATION, sine(2.0, 0.4), sine(6.0, 0.25)),
        run_trial(  # a sustained lean to about 3.5 m/s, then braking, while weaving
            board,
            mass,
            DURATION,
            piecewise([0.5, 3.5, 5.0], [2 * PITCH_TORQUE, -2 * PITCH_TORQUE, 0.0]),
            sine(KNEE_TORQUE / 2, 0.3),
        ),
    ]
    return fit, held_out


def identify(board: Board) -> IdentificationResult:
    """Identify the reduced model of a Segway carrying a dead weight of its rider's mass.

    Raises:
        IdentificationFailed: A trial fell, the fit is ill-conditioned or non-physical, or a
            held-out NRMSE exceeds ``MAX_NRMSE``.
    """
    from ridempc.robots import load_robot  # the rider's mass only

    params = board.params
    if not isinstance(params, SegwayParameters):
        raise IdentificationFailed(f"board '{board.name}' is not a Segway")
    weight = load_robot(params.dead_weight_robot).mass
    mass = board.mass + weight
    fit_trials, held_out = _trials(board, weight)
    if any(t.fell for t in (*fit_trials, *held_out)):
        raise IdentificationFailed(f"board '{board.name}': a trial fell")
    reduced = fit_reduced(fit_trials, mass)
    fit = _worst([score_trial(reduced, t) for t in held_out])
    paper = _worst([score_trial(fit_reduced(fit_trials, mass, full=False), t) for t in held_out])
    bad = {k: v for k, v in fit.items() if k.endswith("_nrmse") and not v <= MAX_NRMSE}
    if bad:
        raise IdentificationFailed(
            f"board '{board.name}': held-out error beyond {MAX_NRMSE}: "
            + ", ".join(f"{k} = {v:.3g}" for k, v in bad.items())
        )
    top = max(float(np.max(np.abs(t.speed))) for t in (*fit_trials, *held_out))
    return IdentificationResult(
        board=board.name,
        model="Segway closed loop: pitch (4'), speed (8'), yaw-rate lag (5'), unicycle (6-7)",
        parameters=reduced.model_dump(),
        units=UNITS,
        fit=fit,
        trials_fit=len(fit_trials),
        trials_held_out=len(held_out),
        notes=(
            f"dead weight {weight:.2f} kg ({params.dead_weight_robot}); {DURATION:.0f} s trials "
            f"at {1.0 / fit_trials[0].dt:.0f} Hz; pitch torque +-{PITCH_TORQUE} N m, knee "
            f"torque +-{KNEE_TORQUE} N m; fastest {top:.2f} m/s; fit figures are the worst "
            "held-out trial's; paper_form_* is the fit without c6, c7"
        ),
        extra={f"paper_form_{k}": v for k, v in paper.items()},
    )
