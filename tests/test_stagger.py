"""The rider's periodic jobs on separate ticks (``ridempc.mpc.stagger``), without a ride."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from ridempc.mpc.handover import BLEND_S, STANDBY_DIVIDER, Handover
from ridempc.mpc.rider import MPC_DIVIDER, MpcRider
from ridempc.mpc.stagger import standby_phase
from ridempc.robots.robot import load_robot
from ridempc.sim.motors import MotorCommand


@pytest.mark.parametrize("latency", range(MPC_DIVIDER))
def test_the_standby_takes_neither_the_mpc_tick_nor_the_plans(latency: int) -> None:
    phase = standby_phase(MPC_DIVIDER, latency)
    assert 0 < phase < MPC_DIVIDER and phase != latency


def test_half_a_period_after_the_mpc_where_the_plan_is_not_taken_up() -> None:
    assert [standby_phase(15, latency) for latency in (0, 1, 2, 7, 8)] == [7, 7, 7, 8, 7]
    assert standby_phase(3, 1) == 2 and standby_phase(4, 2) == 3


def test_the_standby_shares_the_mpc_period() -> None:
    # a standby of another period would land on the MPC's tick every few periods
    assert STANDBY_DIVIDER == MPC_DIVIDER


@pytest.mark.parametrize(("period", "latency"), [(2, 0), (15, 15), (15, -1)])
def test_a_period_with_no_free_tick_or_a_latency_outside_it_is_refused(
    period: int, latency: int
) -> None:
    with pytest.raises(ValueError, match="allowed"):
        standby_phase(period, latency)


class _Backup:
    """A backup law that records the ticks it ran on."""

    def __init__(self) -> None:
        self.ran: list[int] = []

    def update(self, sensors: Any, command: Any) -> MotorCommand:
        self.ran.append(round(sensors.time / 0.002))
        return MotorCommand.hold((), np.zeros(0))


def test_the_handover_runs_the_standby_on_its_phase() -> None:
    backup = _Backup()
    handover = Handover(backup, standby_every=15, standby_phase=8)  # type: ignore[arg-type]
    for k in range(40):
        primary = MotorCommand.hold((), np.zeros(0))
        handover.step(SimpleNamespace(time=k * 0.002), None, primary, None, True)  # type: ignore[arg-type]
    assert backup.ran == [0, 8, 23, 38]  # its first tick, then the phase of each period


@pytest.mark.parametrize("latency", [0, 2, 7])
def test_the_rider_staggers_its_standby(latency: int) -> None:
    rider = MpcRider(load_robot("cassie"), "hovershoes", plan_latency=latency)
    handover = rider.handover
    # in full every tick over the ride's first second on probation (its filters settle from
    # rest), then every STANDBY_DIVIDER-th tick
    assert handover.standby_every == 1 and handover.blend_s == BLEND_S
    assert rider._standby_every == STANDBY_DIVIDER
    assert handover.standby_phase == standby_phase(MPC_DIVIDER, latency)
