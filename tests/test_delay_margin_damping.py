"""The damping of largest phase margin through a motor's delay
(:func:`~ridempc.robots.delay_margin.best_damping`), and the MPC rider's tracking dampings
picked by it (:func:`~ridempc.robots.delay_margin.tracking_damping`)."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from ridempc.mpc.riding_posture import ride_qpos
from ridempc.robots import load_robot
from ridempc.robots.delay_margin import (
    best_damping,
    effective_delay,
    joint_inertias,
    phase_margin,
    tracking_damping,
)
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ

STEP = 1.0 / DEFAULT_PHYSICS_HZ


@pytest.mark.parametrize("seed", range(6))
def test_no_other_damping_has_a_larger_margin(seed: int) -> None:
    rng = np.random.default_rng(seed)
    inertia, kp, delay = rng.uniform([0.005, 5.0, 0.001], [1.0, 3000.0, 0.006])
    kd = best_damping(inertia, kp, delay)
    grid = np.geomspace(kd / 30.0, kd * 30.0, 20_001)
    margins = [phase_margin(inertia, kp, d, delay) for d in grid]
    assert kd == pytest.approx(grid[int(np.argmax(margins))], rel=1e-3)
    assert phase_margin(inertia, kp, kd, delay) >= max(margins) - 1e-12


def test_the_knee_in_the_segway_crouch_gains_its_margin_from_the_damping() -> None:
    # Cassie's knee in the Segway crouch (0.103 kg m^2) under the MPC rider's 0.1 stiffness
    # (300 N m / rad) through 5 steps: 4 deg at the scaled default damping, 53 at the best.
    delay = effective_delay(5, STEP)
    assert math.degrees(phase_margin(0.103, 300.0, 1.5, delay)) == pytest.approx(4.0, abs=0.5)
    kd = best_damping(0.103, 300.0, delay)
    assert kd == pytest.approx(11.8, abs=0.05)
    assert math.degrees(phase_margin(0.103, 300.0, kd, delay)) == pytest.approx(53.1, abs=0.1)


def test_the_riders_delayed_motors_get_the_best_damping_the_others_keep_theirs() -> None:
    cassie = load_robot("cassie")
    qpos = ride_qpos(cassie, "segway")
    kp = 0.1 * np.array([m.kp for m in cassie.motors])
    kd = 0.1 * np.array([m.kd for m in cassie.motors])
    damped = tracking_damping(cassie.mj_model, qpos, cassie.motors, kp, kd, STEP)
    assert np.all(damped > kd)  # every loop was short of damping through the delay
    model, data = cassie.mj_model, mujoco.MjData(cassie.mj_model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, m.joint) for m in cassie.motors]
    inertias = joint_inertias(model, data, np.array([model.jnt_dofadr[j] for j in joints]))
    delay = effective_delay(5, STEP)  # 3 ms at 1500 Hz
    for i, inertia in enumerate(inertias):
        best = phase_margin(inertia, kp[i], damped[i], delay)
        assert best > math.radians(30.0)
        for factor in (0.8, 1.25):
            assert phase_margin(inertia, kp[i], factor * damped[i], delay) < best
    # a motor without a delay keeps the damping it was given, to the bit
    undelayed = tuple(
        dataclasses.replace(m, torque_delay=0.0) if i % 2 else m
        for i, m in enumerate(cassie.motors)
    )
    mixed = tracking_damping(cassie.mj_model, qpos, undelayed, kp, kd, STEP)
    assert np.array_equal(mixed[1::2], kd[1::2])
    assert np.array_equal(mixed[0::2], damped[0::2])
    dog = load_robot("cyberdog2")
    dog_kd = np.array([m.kd for m in dog.motors])
    same = tracking_damping(
        dog.mj_model, dog.stand_qpos, dog.motors, np.array([m.kp for m in dog.motors]), dog_kd, STEP
    )
    assert np.array_equal(same, dog_kd)
