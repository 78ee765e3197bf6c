"""System identification of a board's reduced model from simulated experiments.

Each kind's ``identify(board)`` loads the physical board (MuJoCo, with its firmware) with a
dead weight, runs scripted experiments, fits the reduced model's parameters on some trials
and scores the fit on held-out ones. Its :class:`IdentificationResult` is printed by
``ridempc board identify`` and, once reviewed, its parameters are copied into the board's
``[reduced]`` table in ``board.toml``, which the planners and the MPC read.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ridempc.errors import RidempcError

__all__ = ["IdentificationFailed", "IdentificationResult", "nrmse", "r_squared"]


def nrmse(measured: NDArray[np.float64], predicted: NDArray[np.float64]) -> float:
    """RMSE over the measured signal's range [-] (inf for a constant signal)."""
    span = float(np.ptp(measured))
    rmse = float(np.sqrt(np.mean((measured - predicted) ** 2)))
    return rmse / span if span > 0 else float("inf")


def r_squared(measured: NDArray[np.float64], predicted: NDArray[np.float64]) -> float:
    """Coefficient of determination :math:`1 - SS_{res} / SS_{tot}` [-]."""
    total = float(np.sum((measured - measured.mean()) ** 2))
    residual = float(np.sum((measured - predicted) ** 2))
    return 1.0 - residual / total if total > 0 else float("-inf")


class IdentificationFailed(RidempcError):
    """The fit did not converge, or its held-out error is beyond use; nothing is written."""


@dataclass(frozen=True)
class IdentificationResult:
    """An identified reduced model.

    Attributes:
        board: Board name.
        model: Which reduced model (with the paper's equation numbers).
        parameters: Identified values, by name.
        units: Unit of each parameter, by name.
        fit: Held-out fit figures: ``<signal>_r2`` (coefficient of determination) and
            ``<signal>_nrmse`` (RMSE over the signal's range), by signal.
        trials_fit: Number of trials used to fit.
        trials_held_out: Number of held-out trials scored.
        notes: Anything worth knowing about the experiments.
    """

    board: str
    model: str
    parameters: dict[str, float]
    units: dict[str, str]
    fit: dict[str, float]
    trials_fit: int
    trials_held_out: int
    notes: str = ""
    extra: dict[str, float] = field(default_factory=dict)

    def table(self) -> str:
        lines = [f"{self.board}: {self.model}"]
        for name, value in self.parameters.items():
            lines.append(f"  {name:<12} = {value:12.6g} {self.units.get(name, '')}")
        lines.append(f"  held-out fit ({self.trials_held_out} trials, {self.trials_fit} fitted):")
        for name, value in self.fit.items():
            lines.append(f"  {name:<24} {value:8.4f}")
        return "\n".join(lines)
