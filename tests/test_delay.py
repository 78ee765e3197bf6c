"""Delay-compensated plans: the MPC solved from the state predicted at its take-up."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.mpc.delay import predicted_start
from ridempc.mpc.rider import MPC_DIVIDER, MpcRider
from ridempc.robots import load_robot
from ridempc.scenarios import resolve_scenario
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.sim.simulation import Simulation


@pytest.fixture(scope="module")
def dog():
    return load_robot("cyberdog2")


def test_the_start_is_the_state_carried_over_the_delay_by_the_reduced_model(dog) -> None:
    """The prediction is one step of the reduced model's rates (CasADi's own ``rates``
    here, not the compiled Jacobians the prediction calls) with the previous input and
    the drift; no delay leaves the state as it is."""
    mpc = MpcRider(dog, "skateboard").mpc
    reference, model, dt = mpc.reference, mpc.model, mpc.settings.dt
    rng = np.random.default_rng(0)
    t = 0.5
    window = reference.sample(t, 1, dt)
    x0 = window.states[0] + 0.01 * rng.standard_normal(model.nx)
    u = window.inputs[0] + rng.standard_normal(model.nu)
    drift = 0.1 * rng.standard_normal(model.nx)
    assert predicted_start(model, reference, t, x0, u, drift, 0.0, dt) is x0
    delay = 0.004  # [s] two control ticks
    rates = np.asarray(model.rates(x0, u, window.parameters[0])).ravel()
    expected = x0 + delay * (rates + drift)
    got = predicted_start(model, reference, t, x0, u, drift, delay, dt)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
    without = predicted_start(model, reference, t, x0, u, None, delay, dt)
    np.testing.assert_allclose(without, x0 + delay * rates, rtol=1e-12, atol=1e-12)


def test_a_late_plan_starts_at_its_take_up(dog, monkeypatch) -> None:
    """With a ``plan_latency`` every plan but the first (waited for) is timed from the
    tick it takes over, its start predicted there; without the prediction it is timed
    from the tick its state was estimated (the plan's time shifted), a different ride
    (the MPC from the first tick, not after the pair's PD start)."""
    monkeypatch.setattr("ridempc.mpc.rider_parts.start_readiness", lambda *args: None)
    rides = {}
    for predicts in (True, False):
        rider = MpcRider(dog, "skateboard", plan_latency=2)
        rider.off_tick = "tick"
        rider.predicts_start = predicts
        taken: list[tuple[int, float]] = []
        adopt = rider._adopt

        def adopting(solve, built, rider=rider, adopt=adopt, taken=taken):
            adopt(solve, built)
            taken.append((rider._tick, rider.book.time))

        rider._adopt = adopting
        scenario = resolve_scenario("stand-still", "skateboard").with_duration(0.2)
        scene = build_scene(dog, DEFAULT_PHYSICS_HZ, board=load_board("skateboard"))
        rides[predicts] = Simulation(scene, rider, scenario).run()
        assert rides[predicts].status == "ok"
        ticks = [tick for tick, _ in taken]
        assert ticks == [0] + [k * MPC_DIVIDER + 2 for k in range(1, len(taken))]
        start = taken[0][1]  # the first tick's time
        for tick, plan_time in taken[1:]:
            at = tick if predicts else tick - 2
            assert plan_time == pytest.approx(start + at / rider.rate_hz, abs=1e-9)
    assert np.abs(rides[True].log["qpos"][-1] - rides[False].log["qpos"][-1]).max() > 0.0
