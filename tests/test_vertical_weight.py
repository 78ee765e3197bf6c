"""The rider's mass weighed by the MPC's vertical prediction error
(:mod:`ridempc.mpc.vertical_weight`) and the payload stage's choice of weighing.

- A point rider of unknown mass held by a plan that carries the estimated weight: each MPC
  step the plan predicts her vertical velocity, the truth (her own mass) differs by
  :math:`g (m_0 + \\Delta\\hat m - m) / m` over the step, and the estimate settles on her
  true mass within a few time constants, heavier and lighter.
- It is held while the plan is not followed, through a manoeuvre and with a foot off
  contact, and bounded where no payload could be.
- Weighed so, the payload estimator reads no loads: the estimate is the weighed mass with the
  model's centre of mass; the pair file names the weighing and refuses an unknown one.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.mpc.plan import Plan
from ridempc.mpc.vertical_weight import GRAVITY, MASS_BOUND, TIME_CONSTANT_S, VerticalWeight
from ridempc.pair_description import PairDescription, PayloadStage

DT = 1.0 / 30.0  # [s] the MPC's step
MODEL_MASS = 32.8  # [kg] Cassie's model
VZ = 1  # the vertical velocity's row in a two-state (z, vz) model


def _tick(plan: Plan | None, now: float, **kw: object) -> SimpleNamespace:
    """An MPC tick ``DT`` after ``plan``'s start, balancing with both feet on contact."""
    standing = SimpleNamespace(contact=np.ones(2, dtype=bool))
    fields = dict(estimate=standing, now=now, plan=plan, plan_time=now - DT, frame_turn=0.0,
                  held=False, balancing=True)  # fmt: skip
    fields.update(kw)
    return SimpleNamespace(**fields)


def _plan(drift: float) -> Plan:
    """The plan from rest holding the model's mass plus the payload its drift carries: the
    forces :math:`(m_0 + \\Delta\\hat m) g` on a model with the rate
    :math:`F / m_0 - g + d`, which is zero: it predicts rest."""
    force = MODEL_MASS * (GRAVITY - drift)  # [N]
    vz = DT * (force / MODEL_MASS - GRAVITY + drift)
    states = np.array([[0.0, 0.0], [0.0, vz]])
    return Plan(states, np.array([[force]]), np.array([force]), "solved", 0.0, False)


def _weigh(true_mass: float, seconds: float) -> VerticalWeight:
    """The weight estimated over ``seconds`` of a rider of ``true_mass`` [kg]."""
    weight = VerticalWeight(VZ, MODEL_MASS, DT)
    now = 0.0
    for _ in range(round(seconds / DT)):
        plan = _plan(float(weight.observer.estimate[0]))
        force = float(plan.first_input[0])
        truth = np.array([0.0, DT * (force / true_mass - GRAVITY)])  # her vz a step on
        now += DT
        weight.update(_tick(plan, now), truth)  # type: ignore[arg-type]
    return weight


@pytest.mark.parametrize("fraction", [-0.3, -0.1, 0.2, 0.3])
def test_the_weight_settles_on_the_riders_true_mass(fraction: float) -> None:
    true_mass = MODEL_MASS * (1.0 + fraction)
    weight = _weigh(true_mass, 8.0 * TIME_CONSTANT_S)
    assert weight.mass == pytest.approx(true_mass - MODEL_MASS, abs=0.01 * MODEL_MASS)
    # a time constant in, it has taken up most of it, not all: a low pass, not a jump
    early = _weigh(true_mass, TIME_CONSTANT_S).mass / (true_mass - MODEL_MASS)
    assert 0.4 < early < 0.9


@pytest.mark.parametrize(
    "change",
    [
        {"held": True},
        {"balancing": False},
        {"estimate": SimpleNamespace(contact=np.array([True, False]))},
    ],  # fmt: skip
)
def test_the_weight_is_held_unless_a_balancing_rider_stands_on_the_plan(
    change: dict[str, object],
) -> None:
    weight = VerticalWeight(VZ, MODEL_MASS, DT)
    x0 = np.array([0.0, -DT * 3.0])  # sinking against a plan that predicted rest
    for k in (1, 2):  # the first tick starts the observer's clock
        weight.update(_tick(_plan(0.0), k * DT), x0)  # type: ignore[arg-type]
    first = weight.mass
    assert first > 0.0  # heavier than the model: she sinks
    weight.update(_tick(_plan(0.0), 3 * DT, **change), x0)  # type: ignore[arg-type]
    assert weight.mass == first


def test_the_weight_is_bounded_where_no_payload_could_be() -> None:
    weight = VerticalWeight(VZ, MODEL_MASS, DT)
    falling = np.array([0.0, -DT * GRAVITY])  # in free fall: no weight carried at all
    for k in range(1, 100):
        weight.update(_tick(_plan(0.0), k * DT), falling)  # type: ignore[arg-type]
    assert weight.mass == pytest.approx(MASS_BOUND * MODEL_MASS)


def test_a_pair_names_how_its_payload_is_weighed() -> None:
    assert PayloadStage().mass_from == "loads"
    assert PayloadStage(mass_from="prediction").mass_from == "prediction"
    with pytest.raises((ConfigError, ValueError), match="mass_from"):
        PayloadStage(mass_from="scale")  # type: ignore[arg-type]
    assert "payload" in PairDescription.model_fields["stages"].annotation.model_fields  # type: ignore[union-attr]


def test_a_weighed_payload_estimator_reads_no_loads() -> None:
    from ridempc.mpc.payload import PayloadEstimator
    from ridempc.robots import load_robot
    from ridempc.robots.pinocchio_model import build_pinocchio_robot

    robot = load_robot("cassie")
    pinocchio = build_pinocchio_robot(robot)
    estimator = PayloadEstimator(robot, pinocchio, DT)
    estimator.weigh(3.0)
    q = pinocchio.coordinates.qpos_to_pinocchio(robot.stand_qpos)
    imu = SimpleNamespace(quaternion=np.array([1.0, 0, 0, 0]),
                          linear_acceleration=np.array([0.0, 0.0, GRAVITY]))  # fmt: skip
    n = len(estimator.legs.feet)
    for _ in range(15):  # loads that would read a rider half again as heavy, off-centre
        estimator.accumulate(np.array([2.0, 1.0][:n]), np.ones(n, dtype=bool),
                             np.zeros(len(robot.motors)), imu)  # type: ignore[arg-type]  # fmt: skip
    estimate = estimator.update(q, np.array([0.05, 0.0, 0.9]))
    assert estimate.mass == 3.0
    assert np.all(estimate.shift == 0.0)
    assert estimate.drift(4, 1)[1] == pytest.approx(-GRAVITY * 3.0 / estimator.mass0)
