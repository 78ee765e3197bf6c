"""The SRBKM model in CasADi against Pinocchio, and the board side against the reduced model."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from ridempc.boards import load_board
from ridempc.boards.skateboard.reduced import roll_acceleration, yaw_rate
from ridempc.robots import load_robot
from ridempc.robots.pinocchio_model import build_pinocchio_robot
from ridempc.trajopt.rigid_body import (
    GRAVITY,
    build_rigid_body_robot,
    feet_world,
    rigid_body_rates,
)
from ridempc.trajopt.rotations import euler_rate_map, euler_zyx_matrix
from ridempc.trajopt.skateboard import deck_frame, skateboard_model, skateboard_rates

STANCES = {"cyberdog2": "skate", "cassie": "stand"}


@pytest.fixture(scope="module", params=sorted(STANCES))
def models(request):
    robot = load_robot(request.param)
    srb = build_rigid_body_robot(robot, STANCES[request.param])
    return robot, srb, build_pinocchio_robot(robot)


def _pinocchio_q(srb, pinned, q_joints, trunk_position, rotation):
    q = srb.q_full_reference.copy()
    q[:3] = trunk_position
    q[3:7] = pin.Quaternion(rotation).coeffs()  # x, y, z, w
    for k, joint in enumerate(srb.joints):
        q[pinned.model.joints[pinned.model.getJointId(joint)].idx_q] = q_joints[k]
    return q


def test_mass_com_and_composite_inertia_match_pinocchio(models) -> None:
    robot, srb, pinned = models
    model, data = pinned.model, pinned.model.createData()
    q = srb.q_full_reference
    assert srb.mass == pytest.approx(robot.mass, rel=1e-9)
    assert np.allclose(srb.com_in_trunk, pin.centerOfMass(model, data, q), atol=1e-12)
    # Composite inertia summed body by body (independent of ccrba).
    pin.forwardKinematics(model, data, q)
    total = pin.Inertia.Zero()
    for j in range(1, model.njoints):
        total += data.oMi[j].act(model.inertias[j])
    assert total.mass == pytest.approx(srb.mass)
    assert np.allclose(total.lever, srb.com_in_trunk, atol=1e-12)
    assert np.allclose(total.inertia, srb.inertia, atol=1e-10)
    assert np.allclose(srb.inertia, srb.inertia.T)
    assert np.all(np.linalg.eigvalsh(srb.inertia) > 0)


def test_feet_in_world_match_pinocchio(models) -> None:
    _, srb, pinned = models
    model, data = pinned.model, pinned.model.createData()
    rng = np.random.default_rng(3)
    for _ in range(10):
        q_joints = rng.uniform(np.maximum(srb.q_lower, -3), np.minimum(srb.q_upper, 3))
        euler = rng.uniform(-0.5, 0.5, 3)
        com = rng.uniform(-1.0, 1.0, 3)
        rotation = euler_zyx_matrix(*euler)
        trunk = com - rotation @ srb.com_in_trunk
        pin.framesForwardKinematics(
            model, data, _pinocchio_q(srb, pinned, q_joints, trunk, rotation)
        )
        ours = feet_world(srb, com, euler, q_joints, xp=np)
        for k, site in enumerate(srb.feet):
            assert np.allclose(ours[k], data.oMf[model.getFrameId(site)].translation, atol=1e-10)
        # The symbolic version gives the same numbers.
        symbolic = feet_world(srb, ca.DM(com), ca.DM(euler), ca.DM(q_joints))
        assert np.allclose(np.asarray(symbolic[0]).ravel(), ours[0], atol=1e-12)


def test_foot_jacobians_match_pinocchio(models) -> None:
    _, srb, pinned = models
    model, data = pinned.model, pinned.model.createData()
    q_sym = ca.SX.sym("q", srb.n_joints)
    jacobians = ca.Function("j", [q_sym], [srb.foot_jacobian(q_sym, i) for i in range(srb.n_feet)])
    rng = np.random.default_rng(5)
    columns = [model.joints[model.getJointId(j)].idx_v for j in srb.joints]
    for _ in range(5):
        q_joints = rng.uniform(np.maximum(srb.q_lower, -3), np.minimum(srb.q_upper, 3))
        q = _pinocchio_q(srb, pinned, q_joints, np.zeros(3), np.eye(3))
        pin.computeJointJacobians(model, data, q)
        pin.framesForwardKinematics(model, data, q)
        ours = jacobians(q_joints)
        for k, site in enumerate(srb.feet):
            reference = pin.getFrameJacobian(
                model, data, model.getFrameId(site), pin.LOCAL_WORLD_ALIGNED
            )[:3, columns]
            assert np.allclose(np.asarray(ours[k]), reference, atol=1e-10)


def test_legs_and_limits_come_from_the_description(models) -> None:
    robot, srb, _ = models
    motors = {m.joint: m for m in robot.motors}
    assert srb.joints == tuple(motors)
    assert np.allclose(srb.torque_limit, [motors[j].torque_limit for j in srb.joints], rtol=1e-4)
    assert np.allclose(srb.speed_limit, [motors[j].speed_limit for j in srb.joints])
    assert all(srb.q_lower < srb.q_upper)
    for leg in srb.legs:
        assert leg  # every foot is moved by some motor


def test_cyberdog_legs_and_foot_radius() -> None:
    srb = build_rigid_body_robot(load_robot("cyberdog2"), "skate")
    assert srb.legs == ((0, 1, 2), (3, 4, 5), (6, 7, 8), (9, 10, 11))
    assert np.allclose(srb.foot_radius, 0.019)
    assert srb.mass == pytest.approx(8.9)


def test_euler_rate_map_matches_the_rotation_derivative() -> None:
    rng = np.random.default_rng(1)
    for _ in range(5):
        euler = rng.uniform(-0.6, 0.6, 3)
        omega = rng.uniform(-1, 1, 3)
        h = 1e-6
        rotation = euler_zyx_matrix(*euler)
        rates = euler_rate_map(euler[0], euler[1]) @ omega
        numeric = (euler_zyx_matrix(*(euler + h * rates)) - rotation) / h
        skew = np.array(
            [[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]]
        )
        assert np.allclose(numeric, rotation @ skew, atol=1e-5)


def test_rigid_body_rates_balance_and_newton_euler() -> None:
    srb = build_rigid_body_robot(load_robot("cyberdog2"), "skate")
    com = np.array([0.1, -0.2, 0.4])
    state = np.concatenate([com, [0.1, -0.05, 0.3], np.zeros(6), srb.q_reference])
    points = [com + np.array([0.2, 0.1, -0.3]), com + np.array([-0.2, -0.1, -0.3])]
    weight = np.array([0.0, 0.0, srb.mass * GRAVITY / 2])
    balanced = np.asarray(
        rigid_body_rates(
            srb,
            ca.DM(state),
            [ca.DM(weight)] * 2,
            [ca.DM(p) for p in points],
            ca.DM.zeros(srb.n_joints),
        )
    ).ravel()
    assert np.allclose(balanced[6:12], 0.0, atol=1e-12)  # weight carried, no net moment
    # A pure force couple spins the body: I w_dot = R^T (r x f).
    f = np.array([0.0, 5.0, 0.0])
    rates = np.asarray(
        rigid_body_rates(
            srb,
            ca.DM(state),
            [ca.DM(f), ca.DM(-f)],
            [ca.DM(p) for p in points],
            ca.DM.zeros(srb.n_joints),
        )
    ).ravel()
    moment = np.cross(points[0] - com, f) + np.cross(points[1] - com, -f)
    rotation = euler_zyx_matrix(*state[3:6])
    assert np.allclose(srb.inertia @ rates[9:12], rotation.T @ moment, atol=1e-10)
    assert np.allclose(rates[6:9], [0, 0, -GRAVITY])


def test_skateboard_rates_follow_the_reduced_model() -> None:
    board = skateboard_model(load_board("skateboard"))
    state = np.array([0.3, -0.1, 0.2, 0.8, 0.05, -0.2])
    rotation, origin = deck_frame(board, ca.DM(state))
    rotation, origin = np.asarray(rotation), np.asarray(origin).ravel()
    point = origin + rotation @ np.array([0.1, 0.08, 0.0])
    force = np.array([2.0, -1.0, 20.0])  # on the robot; the deck gets -force
    rates = np.asarray(
        skateboard_rates(board, ca.DM(state), [ca.DM(force)], [ca.DM(point)])
    ).ravel()
    r = board.reduced
    torque = -(rotation.T @ np.cross(point - origin, force))[0]
    assert rates[5] == pytest.approx(
        roll_acceleration(
            state[4], state[5], torque, r.roll_inertia, r.roll_stiffness, r.roll_damping
        )
    )
    assert rates[2] == pytest.approx(yaw_rate(state[3], state[4], r.steer_gain))
    assert rates[0] == pytest.approx(state[3] * np.cos(state[2]))
    drag = np.tanh(board.friction_sharpness * state[3]) * board.friction_force
    drag += board.viscous_drag * state[3]
    assert rates[3] == pytest.approx((-(rotation.T @ force)[0] - drag) / board.mass)
    assert board.mass == pytest.approx(2.8 + 0.4)
