"""The delayed joint PD's phase margin (:mod:`ridempc.robots.delay_margin`), and the robots'
hold gains checked against it at their stand keyframe."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from ridempc.robots import load_robot
from ridempc.robots.delay_margin import effective_delay, gain_bound, joint_inertias, phase_margin
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.motors import delay_steps

STEP = 1.0 / DEFAULT_PHYSICS_HZ


def _loop(inertia: float, kp: float, kd: float, delay: float, w: np.ndarray) -> np.ndarray:
    s = 1j * w
    return (kp + kd * s) * np.exp(-s * delay) / (inertia * s**2)


@pytest.mark.parametrize("seed", range(4))
def test_the_margin_is_the_loops_phase_at_its_crossover(seed: int) -> None:
    rng = np.random.default_rng(seed)
    inertia, kp, kd, delay = rng.uniform([0.01, 10.0, 0.5, 0.001], [1.0, 3000.0, 50.0, 0.005])
    w = np.geomspace(1.0, 1e5, 200_001)
    loop = _loop(inertia, kp, kd, delay, w)
    i = np.argmin(np.abs(np.abs(loop) - 1.0))
    # the phase of L plus pi, wrapped to (-pi, pi]
    expected = np.angle(loop[i] * -1.0)
    assert phase_margin(inertia, kp, kd, delay) == pytest.approx(expected, abs=1e-3)


@pytest.mark.parametrize("margin", [math.pi / 6, math.pi / 4, math.pi / 3])
def test_the_bound_has_the_margin_asked_for(margin: float) -> None:
    inertia, delay = 0.1, effective_delay(5, STEP)
    kp, kd = gain_bound(inertia, delay, margin)
    assert phase_margin(inertia, kp, kd, delay) == pytest.approx(margin, abs=1e-9)
    assert kd * math.sqrt(1.0 + 0.25) * delay == pytest.approx(inertia * (math.atan(2.0) - margin))


def _keyframe_inertias(robot, keyframe: str) -> np.ndarray:
    """Each motor's joint inertia at ``keyframe``, the rest of the robot free [kg m^2]."""
    model = robot.mj_model
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, keyframe)
    mujoco.mj_resetDataKeyframe(model, data, key)
    mujoco.mj_forward(model, data)
    joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, m.joint) for m in robot.motors]
    return joint_inertias(model, data, np.array([model.jnt_dofadr[j] for j in joints]))


# Joints whose loop is closed on the foot: standing, the toe turns the whole robot about the
# foot (about 1 kg m^2 on Cassie, not the foot's 0.013), so the free-joint model does not bound
# its gains; robots/cassie/README.md, "The hold gains under the torque delay".
FOOT_JOINTS = ("toe",)


def test_the_hold_gains_keep_the_delayed_loops_stable(robot) -> None:
    """Every motor with a delay, but the feet's, is stable by the single-joint model at the
    stand keyframe (the stand hold and, at a tenth, the MPC rider's tracking)."""
    inertias = _keyframe_inertias(robot, robot.params.stand_keyframe)
    for motor, inertia in zip(robot.motors, inertias, strict=True):
        steps = delay_steps(motor.torque_delay, STEP)
        if steps == 0 or motor.name.endswith(FOOT_JOINTS):
            continue
        margin = phase_margin(inertia, motor.kp, motor.kd, effective_delay(steps, STEP))
        assert margin > 0.0, (motor.name, inertia, math.degrees(margin))


def _pd_riders():
    from ridempc.baselines.cassie_segway_gains import load_segway_gains
    from ridempc.baselines.cassie_standing_gains import load_standing_gains
    from ridempc.baselines.hovershoe_gains import load_hovershoes_gains

    return {
        # rider: (its joint gains, the keyframe it holds, the least margin it keeps [deg])
        "standing": (load_standing_gains().joints, "stand", 5.0),
        "hovershoes": (load_hovershoes_gains().standing.joints, "stand", 5.0),
        # the crouch's load is the statics' feedforward: the knee can be soft and well inside
        "segway": (load_segway_gains().standing.joints, "ride_segway_crouch", 40.0),
    }


@pytest.mark.parametrize("rider", ["standing", "hovershoes", "segway"])
def test_the_pd_riders_hip_pitch_and_knee_keep_a_margin(rider: str) -> None:
    """Cassie's `pd` riders' hip pitch and knee loops are stable through the motor delay at
    the keyframe they hold (at the old 1000/100 and 3000/50 the knee and hip pitch chattered
    at the curve's limit); the toe is the foot's (:data:`FOOT_JOINTS`)."""
    joints, keyframe, least = _pd_riders()[rider]
    cassie = load_robot("cassie")
    names = [m.name for m in cassie.motors]
    inertias = dict(zip(names, _keyframe_inertias(cassie, keyframe), strict=True))
    for name, gains in (("left_hip_pitch", joints.hip_pitch), ("left_knee", joints.knee)):
        motor = next(m for m in cassie.motors if m.name == name)
        delay = effective_delay(delay_steps(motor.torque_delay, STEP), STEP)
        margin = phase_margin(inertias[name], gains.kp, gains.kd, delay)
        assert margin > math.radians(least), (name, math.degrees(margin))
