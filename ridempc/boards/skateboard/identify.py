"""Identification of the skateboard's reduced model (eqs. 6-7 and 14) from simulated trials.

The physical board (MuJoCo, with its no-op firmware) carries a dead weight of the rider's
mass (``dead_weight_robot``, the 8.9 kg CyberDog2) in two families of experiments
(:mod:`.experiments`):

**Roll trials** (board standing): scripted roll torques on the deck (multisines, a chirp,
steps). Eq. (7)'s roll row, integrated over windows of ``WINDOW`` physics steps so that no
acceleration has to be differentiated,

.. math:: I_{Bx} [\\psi]_{t_0}^{t_1} + K_B \\int \\varphi\\, dt + B_B \\int \\psi\\, dt
          = \\int \\tau\\, dt,

is a linear least-squares problem in :math:`(I_{Bx}, K_B, B_B)`, fitted on some trials and
scored on held-out ones by integrating the model from the held-out trial's initial state
under its recorded torque and comparing the roll (NRMSE = RMSE / range, and R^2). Two
torques give two models:

- the paper's (eqs. 6-7): :math:`\\tau` = scripted torque + the rider's roll torque (the
  contact wrench of the weight on the deck, about the platform site): the board alone;
- the *loaded* deck (reported in ``extra``): :math:`\\tau` = scripted torque only, the
  weight counted in the rolling body, as when a rider's roll torque is a weight shift.

**Steering trials** (board pushed to a speed, roll held by the experimenter): the gain of
eq. (14), :math:`\\omega = -g\\, v \\sin\\varphi` with :math:`g = 1 / K_{board}`, fitted by
least squares and compared with the geometric :math:`(\\cot\\gamma_f + \\cot\\gamma_r)/L`;
scored on held-out trials by the yaw-rate NRMSE and by integrating the Dubins-like
kinematics from measured speed and roll (heading NRMSE, final position error per metre
travelled).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.boards.identification import (
    IdentificationFailed,
    IdentificationResult,
    nrmse,
    r_squared,
)
from ridempc.boards.skateboard.experiments import (
    RollHold,
    SteeringTrial,
    TrialRecord,
    chirp,
    multisine,
    run_roll_trial,
    run_steering_trial,
    skateboard_scene,
    steps,
)
from ridempc.boards.skateboard.parameters import SkateboardParameters
from ridempc.boards.skateboard.reduced import dubins_rates, simulate_roll, steer_gain
from ridempc.robots import load_robot

__all__ = [
    "MAX_CONDITION",
    "MAX_HELD_OUT_NRMSE",
    "ROLL_TRIALS",
    "STEERING_TRIALS",
    "fit_roll",
    "fit_steer_gain",
    "identify",
    "predict_dubins",
    "roll_regression",
]

Array = NDArray[np.float64]
TorqueOf = Callable[[TrialRecord], Array]

WINDOW = 15  # physics steps per integration window (10 ms at 1500 Hz)
MAX_CONDITION = 1e3  # of the column-scaled regressor
MAX_HELD_OUT_NRMSE = 0.15  # beyond this the reduced model is no use
STEER_START = 1.2  # [s] speed reached and roll hold settled in steering trials
TRIAL_DURATION = 4.0  # [s]

# (name, scripted roll torque [N m], held out)
ROLL_TRIALS: tuple[tuple[str, Callable[[float], float], bool], ...] = (
    ("multisine", multisine(4.0, (0.3, 0.7, 1.3, 2.1, 3.4, 5.5), seed=0), False),
    ("chirp", chirp(3.5, 0.2, 6.0, TRIAL_DURATION), False),
    ("steps", steps((0.0, 3.0, -2.0, 5.0, -4.0, 1.0, -5.0, 2.0), 0.5), False),
    ("multisine-held-out", multisine(4.5, (0.4, 0.9, 1.7, 2.6, 4.2), seed=1), True),
    ("steps-held-out", steps((1.0, -3.0, 4.0, 0.0, -5.0, 3.0, -1.0, 4.5), 0.5), True),
)

# (trial, held out): speeds [m/s], roll references [rad]
STEERING_TRIALS: tuple[tuple[SteeringTrial, bool], ...] = (
    (SteeringTrial("slow-weave", 0.6, RollHold(1.0, 0.0, 0.1, 3.0), TRIAL_DURATION), False),
    (SteeringTrial("weave", 1.2, RollHold(1.0, 0.0, 0.1, 3.0), TRIAL_DURATION), False),
    (SteeringTrial("fast-weave", 1.8, RollHold(1.0, 0.0, 0.08, 3.0), TRIAL_DURATION), False),
    (SteeringTrial("carve-held-out", 1.0, RollHold(1.0, 0.06, 0.06, 2.0), TRIAL_DURATION), True),
    (SteeringTrial("turn-held-out", 1.5, RollHold(1.0, -0.08), TRIAL_DURATION), True),
)


def _paper_torque(record: TrialRecord) -> Array:
    return record.torque_external + record.torque_rider


def _loaded_torque(record: TrialRecord) -> Array:
    return record.torque_external


def roll_regression(
    records: Sequence[TrialRecord], torque_of: TorqueOf, window: int = WINDOW
) -> tuple[Array, Array]:
    """Eq. (7)'s roll row integrated over windows: ``A @ (I, K, B) = b``.

    Args:
        records: Roll trials.
        torque_of: The torque :math:`\\tau` [N m] of a trial.
        window: Samples per window.

    Returns:
        ``A`` rows :math:`([\\psi], \\int\\varphi, \\int\\psi)` and ``b`` rows
        :math:`\\int\\tau`, all by left rectangles (the physics holds each torque a step).
    """
    rows, rhs = [], []
    for record in records:
        dt = float(record.time[1] - record.time[0])

        def integral(signal: Array, dt: float = dt) -> Array:
            return np.concatenate(([0.0], np.cumsum(signal[:-1]) * dt))

        start = np.arange(0, len(record.time) - window, window)
        end = start + window
        roll_int, rate_int = integral(record.roll), integral(record.roll_rate)
        torque_int = integral(torque_of(record))
        rows.append(
            np.column_stack(
                (
                    record.roll_rate[end] - record.roll_rate[start],
                    roll_int[end] - roll_int[start],
                    rate_int[end] - rate_int[start],
                )
            )
        )
        rhs.append(torque_int[end] - torque_int[start])
    return np.vstack(rows), np.concatenate(rhs)


def fit_roll(
    records: Sequence[TrialRecord], torque_of: TorqueOf
) -> tuple[tuple[float, float, float], float]:
    """Least-squares :math:`(I_{Bx}, K_B, B_B)`; returns them and the equation-error R^2.

    Raises:
        IdentificationFailed: Ill-conditioned regressor or a non-physical estimate.
    """
    a, b = roll_regression(records, torque_of)
    scale = np.linalg.norm(a, axis=0)
    condition = float(np.linalg.cond(a / scale))
    if not math.isfinite(condition) or condition > MAX_CONDITION:
        raise IdentificationFailed(f"roll regressor ill-conditioned (condition {condition:.3g})")
    estimate, *_ = np.linalg.lstsq(a, b, rcond=None)
    inertia, stiffness, damping = (float(x) for x in estimate)
    if inertia <= 0.0 or stiffness <= 0.0 or damping < 0.0:
        raise IdentificationFailed(
            f"non-physical roll estimate I = {inertia:.3g}, K = {stiffness:.3g}, B = {damping:.3g}"
        )
    return (inertia, stiffness, damping), r_squared(b, a @ estimate)


def predict_roll(
    record: TrialRecord, torque_of: TorqueOf, model: tuple[float, float, float]
) -> Array:
    """The roll [rad] eq. (7) predicts from the trial's initial state and torque."""
    states = simulate_roll(
        record.time, torque_of(record), (record.roll[0], record.roll_rate[0]), *model
    )
    return states[:, 0]


def fit_steer_gain(records: Sequence[TrialRecord]) -> float:
    """Least-squares :math:`g` in :math:`\\omega = -g v \\sin\\varphi` (eq. 14) [1/m]."""
    regressor = np.concatenate([-r.speed * np.sin(r.roll) for r in records])
    measured = np.concatenate([r.yaw_rate for r in records])
    denominator = float(regressor @ regressor)
    if denominator < 1e-6:
        raise IdentificationFailed("steering trials have no turning to fit the gain on")
    return float(regressor @ measured) / denominator


def predict_dubins(record: TrialRecord, gain: float) -> tuple[Array, Array]:
    """Heading [rad] and :math:`C_B` position [m] from the Dubins-like kinematics (eq. 14),
    integrated from the trial's initial pose with its measured speed and roll."""
    dt = float(record.time[1] - record.time[0])
    heading = np.empty(len(record.time))
    position = np.empty((len(record.time), 2))
    heading[0], position[0] = record.heading[0], record.position[0]
    for k in range(len(record.time) - 1):
        x_rate, y_rate, yaw = dubins_rates(heading[k], record.speed[k], record.roll[k], gain)
        heading[k + 1] = heading[k] + dt * yaw
        position[k + 1] = position[k] + dt * np.array([x_rate, y_rate])
    return heading, position


def _score_roll(
    records: Sequence[TrialRecord], torque_of: TorqueOf, model: tuple[float, float, float]
) -> tuple[float, float]:
    predicted = np.concatenate([predict_roll(r, torque_of, model) for r in records])
    measured = np.concatenate([r.roll for r in records])
    return nrmse(measured, predicted), r_squared(measured, predicted)


def _score_steering(records: Sequence[TrialRecord], gain: float) -> dict[str, float]:
    yaw_pred = np.concatenate([-gain * r.speed * np.sin(r.roll) for r in records])
    yaw_meas = np.concatenate([r.yaw_rate for r in records])
    heading_errors, position_errors = [], []
    for record in records:
        heading, position = predict_dubins(record, gain)
        heading_errors.append(nrmse(record.heading, heading))
        travelled = float(np.sum(np.linalg.norm(np.diff(record.position, axis=0), axis=1)))
        position_errors.append(
            float(np.linalg.norm(position[-1] - record.position[-1])) / travelled
        )
    return {
        "yaw_rate_nrmse": nrmse(yaw_meas, yaw_pred),
        "yaw_rate_r2": r_squared(yaw_meas, yaw_pred),
        "heading_nrmse": float(np.mean(heading_errors)),
        "position_error_per_m": float(np.mean(position_errors)),
    }


def identify(board: Board) -> IdentificationResult:
    """Identify :math:`I_{Bx}, K_B, B_B` (eqs. 6-7) and the steering gain (eq. 14).

    Raises:
        IdentificationFailed: A trial fell or diverged, a fit is ill-conditioned or
            non-physical, or a held-out NRMSE exceeds ``MAX_HELD_OUT_NRMSE``.
    """
    params = board.params
    assert isinstance(params, SkateboardParameters)
    began = time.perf_counter()
    mass = load_robot(params.dead_weight_robot).mass
    scene = skateboard_scene(board, mass)
    roll_fit: list[TrialRecord] = []
    roll_held: list[TrialRecord] = []
    for name, torque, held_out in ROLL_TRIALS:
        record = run_roll_trial(scene, name, torque, TRIAL_DURATION)
        (roll_held if held_out else roll_fit).append(record)
    steer_fit: list[TrialRecord] = []
    steer_held: list[TrialRecord] = []
    for trial, held_out in STEERING_TRIALS:
        record = run_steering_trial(scene, trial).window(STEER_START)
        (steer_held if held_out else steer_fit).append(record)

    paper, paper_r2 = fit_roll(roll_fit, _paper_torque)
    loaded, loaded_r2 = fit_roll(roll_fit, _loaded_torque)
    gain = fit_steer_gain(steer_fit)
    geometric = steer_gain(params)
    roll_nrmse, roll_r2 = _score_roll(roll_held, _paper_torque, paper)
    loaded_nrmse, loaded_r2_held = _score_roll(roll_held, _loaded_torque, loaded)
    fit = {
        "roll_nrmse": roll_nrmse,
        "roll_r2": roll_r2,
        "loaded_roll_nrmse": loaded_nrmse,
        "loaded_roll_r2": loaded_r2_held,
        **_score_steering(steer_held, gain),
        "steer_gain_vs_geometry": gain / geometric - 1.0,
    }
    worst = max(fit["roll_nrmse"], fit["loaded_roll_nrmse"], fit["yaw_rate_nrmse"])
    if not math.isfinite(worst) or worst > MAX_HELD_OUT_NRMSE:
        raise IdentificationFailed(
            f"held-out NRMSE {worst:.3f} exceeds {MAX_HELD_OUT_NRMSE} ({fit})"
        )
    return IdentificationResult(
        board=board.name,
        model="deck roll spring-damper (eqs. 6-7) + Dubins-like steering (eqs. 11-14)",
        parameters={
            "roll_inertia": paper[0],
            "roll_stiffness": paper[1],
            "roll_damping": paper[2],
            "steer_gain": gain,
        },
        units={
            "roll_inertia": "kg m^2",
            "roll_stiffness": "N m / rad",
            "roll_damping": "N m s / rad",
            "steer_gain": "1 / m",
        },
        fit=fit,
        trials_fit=len(roll_fit) + len(steer_fit),
        trials_held_out=len(roll_held) + len(steer_held),
        notes=(
            f"dead weight {mass:.2f} kg ({params.dead_weight_robot}); roll torque of eq. (7) "
            "about the platform site; steering gain from the geometry "
            f"(cot g_f + cot g_r) / L = {geometric:.4f} 1/m"
        ),
        extra={
            "loaded_roll_inertia": loaded[0],
            "loaded_roll_stiffness": loaded[1],
            "loaded_roll_damping": loaded[2],
            "roll_fit_r2": paper_r2,
            "loaded_roll_fit_r2": loaded_r2,
            "steer_gain_geometric": geometric,
            "dead_weight": mass,
            "wall_time": time.perf_counter() - began,
        },
    )
