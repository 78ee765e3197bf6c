"""The whole-body QP's torques led over the motors' delay."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc.robots import load_robot
from ridempc.robots.delay_margin import effective_delay, phase_margin
from ridempc.sim.motors import delay_steps
from ridempc.wbc.torque_lead import TorqueLead

DT = 0.002  # the WBC's tick [s]
PHYSICS = 1.0 / 1500.0  # the simulation's step [s]


def test_each_motor_is_led_by_its_own_delay() -> None:
    cassie = TorqueLead(load_robot("cassie"), DT)
    assert cassie.lead == pytest.approx(np.full(10, 0.003 / DT))
    dog = TorqueLead(load_robot("cyberdog2"), DT)
    assert not dog.lead.any()
    torque = np.linspace(-3.0, 3.0, len(dog.lead))
    dog(0.0, torque + 1.0)
    assert np.array_equal(dog(DT, torque), torque)  # no delay: sent unchanged, to the bit


def test_a_torque_changing_linearly_arrives_as_computed_at_its_arrival() -> None:
    robot = load_robot("cassie")
    lead = TorqueLead(robot, DT)
    delay = np.array([m.torque_delay for m in robot.motors])
    rate = np.linspace(-50.0, 50.0, len(delay))  # [N m / s]
    first = lead(0.0, 1.0 + 0.0 * rate)
    assert np.array_equal(first, np.ones(len(delay)))  # nothing before it
    for k in range(1, 4):
        t = k * DT
        assert lead(t, 1.0 + rate * t) == pytest.approx(1.0 + rate * (t + delay))
    after_gap = 10 * DT  # a failed solve in between: sent as computed
    assert np.array_equal(lead(after_gap, 1.0 + rate * after_gap), 1.0 + rate * after_gap)
    assert np.array_equal(lead(after_gap, 2.0 + rate), 2.0 + rate)  # solved again at once
    lead.reset()
    assert np.array_equal(lead(after_gap + DT, rate), rate)


def _joint_under_the_qp(inertia: float, kp: float, kd: float, led: bool) -> float:
    """The largest |angle| [rad] over the last 0.2 s of 2 s of one joint held by a PD
    computed at the QP's tick and sent through a toe motor's delay line, from 0.01 rad."""
    motor = load_robot("cassie").motors[4]
    lead = TorqueLead(load_robot("cassie"), DT)
    steps, tick = delay_steps(motor.torque_delay, PHYSICS), round(DT / PHYSICS)
    line = [0.0] * (steps + 1)
    angle, rate, sent, tail = 0.01, 0.0, 0.0, []
    for k in range(3000):
        if k % tick == 0:
            torque = np.full(10, -kp * angle - kd * rate)
            sent = float(lead(k * PHYSICS, torque)[4]) if led else float(torque[4])
        line.append(sent)
        rate += PHYSICS * line.pop(0) / inertia
        angle += PHYSICS * rate
        if k >= 2700:
            tail.append(abs(angle))
    return max(tail)


def test_the_lead_gives_back_the_phase_a_fast_loop_loses_in_the_delay() -> None:
    # A foot rocking on an edge (0.0126 kg m^2) under a stiff QP loop: through the delay line
    # and the tick's hold it has no margin left and grows; led over the delay it settles.
    inertia, kp, kd = 0.0126, 200.0, 1.0
    delay = effective_delay(delay_steps(0.003, PHYSICS), PHYSICS) + 0.5 * DT  # and the tick's hold
    assert phase_margin(inertia, kp, kd, delay) < 0.0
    assert phase_margin(inertia, kp, kd, delay - 0.003) > math.radians(5.0)
    assert _joint_under_the_qp(inertia, kp, kd, led=False) > 0.01  # grew
    assert _joint_under_the_qp(inertia, kp, kd, led=True) < 1e-6  # settled
