"""The rider weighed at the ride's first tick (:mod:`ridempc.mpc.start_weight`).

- Cassie on the Segway (its pair with the stage switched on: no pair file uses it, docs/tuning.md,
  session 12), a payload on her pelvis (heavier) or every body scaled (lighter), 30 % either
  way: the first tick's reading weighs her within 5 % of the model's mass, and the nominal rider
  reads no payload; the estimate is in the models before the first plan.
- Weighed once: later readings do not move it; no reading yet (a foot off contact), no weight.
- The pair file names the weighing with its calibration, and refuses either alone.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

import ridempc
from ridempc.controllers.registry import make_controller
from ridempc.errors import ConfigError
from ridempc.mpc.pairs import MpcPair, load_mpc_pair
from ridempc.mpc.start_weight import StartWeight
from ridempc.pair_description import PayloadStage
from ridempc.robots import load_robot

MODEL_MASS = 32.8226  # [kg] Cassie's model
START_READING = 0.9017  # [-] the nominal rider's first reading in ride_segway_crouch

SCENARIO = """name = "stand-still-payload"
duration = 1.0

[[commands]]
t = 0.0
velocity = 0.0
yaw_rate = 0.0

[[changes]]
t = 0.0
parameter = "payload"
body = "base"
mass = {mass}
offset = [0.0, 0.0, 0.0]
"""


@pytest.mark.parametrize("fraction", [-0.3, 0.0, 0.3])
def test_the_first_tick_weighs_the_segway_rider(
    fraction: float, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from ridempc.mpc import rider_parts

    def weighed_pair(robot: str, board: str) -> MpcPair:
        pair = load_mpc_pair(robot, board)
        stage = PayloadStage(mass_from="start", start_reading=START_READING)
        stages = pair.description.stages.model_copy(update={"payload": stage})
        return pair._replace(description=pair.description.model_copy(update={"stages": stages}))

    monkeypatch.setattr(rider_parts, "load_mpc_pair", weighed_pair)
    mass = fraction * MODEL_MASS
    if fraction == 0.0:
        scenario: str | Path = "stand-still"
    else:
        scenario = tmp_path / "payload.toml"
        scenario.write_text(SCENARIO.format(mass=mass))
    rider = make_controller("mpc", load_robot("cassie"), "segway")
    ridempc.ride("cassie", "segway", rider, scenario, duration=0.01)  # the first ticks
    estimate = rider.payload.estimate  # type: ignore[attr-defined]
    assert estimate.mass == pytest.approx(mass, abs=0.05 * MODEL_MASS)
    base = rider.wbc.model.model.inertias[1]  # type: ignore[attr-defined]
    nominal = rider.payload.nominal_inertias[1]  # type: ignore[attr-defined]
    if fraction > 0.0:  # a heavier rider's payload on the base, in the whole-body model
        assert base.mass - nominal.mass == pytest.approx(estimate.mass)
    if fraction == 0.0:
        assert estimate.mass == pytest.approx(0.0, abs=0.01 * MODEL_MASS)


class _Readings:
    """A payload estimator's readings: ``value`` [-], or None (no reading)."""

    def __init__(self, value: float | None) -> None:
        self.value, self.mass0, self.weighed = value, MODEL_MASS, None

    def reading(self) -> float | None:
        return self.value

    def weigh(self, mass: float) -> None:
        self.weighed = mass


def test_the_rider_is_weighed_once_from_the_first_reading() -> None:
    weight = StartWeight(0.9)
    payload = _Readings(None)  # no foot on contact yet
    weight.weigh(payload)  # type: ignore[arg-type]
    assert weight.mass is None and payload.weighed is None
    payload.value = 0.9 * 1.2
    weight.weigh(payload)  # type: ignore[arg-type]
    assert weight.mass == pytest.approx(0.2 * MODEL_MASS)
    payload.value = 0.9 * 0.8  # her sway later
    weight.weigh(payload)  # type: ignore[arg-type]
    assert weight.mass == pytest.approx(0.2 * MODEL_MASS)
    # a reading beyond any payload is bounded
    far = StartWeight(0.9)
    far.weigh(SimpleNamespace(reading=lambda: 0.9 * 3.0, mass0=MODEL_MASS, weigh=lambda m: None))  # type: ignore[arg-type]
    assert far.mass is not None and far.mass < 0.5 * MODEL_MASS


def test_the_pair_file_names_the_start_weighing_with_its_calibration() -> None:
    assert PayloadStage(mass_from="start", start_reading=0.9).start_reading == 0.9
    for wrong in ({"mass_from": "start"}, {"start_reading": 0.9}):
        with pytest.raises((ConfigError, ValueError), match="start_reading"):
            PayloadStage(**wrong)  # type: ignore[arg-type]
