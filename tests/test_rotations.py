"""The rotation module against the NumPy formulas it replaced, on seeded random inputs.

Each reference below is a former hand-written helper, copied verbatim (named for where it
was). The built-ins round differently, so agreement is to a few units in the last place;
conventions (w, x, y, z order, signs, Euler order, angle ranges) must match exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc import rotations

ROUNDING = 1e-13  # a few hundred units in the last place of an angle or a unit entry
COUNT = 2000


def _quaternion_to_matrix(quat_wxyz):  # estimation/rotations.py
    w, x, y, z = quat_wxyz / np.linalg.norm(quat_wxyz)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _matrix_to_quaternion(m):  # estimation/rotations.py
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * np.sqrt(1.0 + trace)
        quat = np.array(
            [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
        )
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        quat = np.empty(4)
        quat[0] = (m[k, j] - m[j, k]) / s
        quat[1 + i] = 0.25 * s
        quat[1 + j] = (m[j, i] + m[i, j]) / s
        quat[1 + k] = (m[k, i] + m[i, k]) / s
    quat /= math.sqrt(quat.dot(quat))
    return quat if quat[0] >= 0.0 else -quat


def _yaw(quat_wxyz):  # estimation/rotations.py, sim/simulation.py, sim/sensors.py
    w, x, y, z = quat_wxyz
    return float(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def _pitch(quat_wxyz):  # boards/segway/firmware.py, boards/segway/experiments.py
    w, x, y, z = quat_wxyz
    return float(np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0)))


def _roll(quat_wxyz):  # boards/skateboard/experiments.py, sim/metrics.py
    w, x, y, z = quat_wxyz
    return math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))


def _rpy_of_matrix(rotation):  # estimation/rotations.py, baselines/cassie_kinematics.py
    roll = float(np.arctan2(rotation[2, 1], rotation[2, 2]))
    pitch = float(-np.arcsin(min(max(rotation[2, 0], -1.0), 1.0)))
    yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
    return roll, pitch, yaw


def _matrix_of_rpy(roll, pitch, yaw):  # estimation/rotations.py, wbc/contacts.py
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _rotation_z(angle):  # baselines/cassie_kinematics.py, baselines/quadruped_skateboard.py
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rotation_y(angle):  # baselines/quadruped_legs.py
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _skew(vector):  # baselines/cassie_statics.py
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _quaternions(rng: np.random.Generator) -> np.ndarray:
    """Random quaternions, each scaled off unit length a little (the helpers normalise)."""
    quats = rng.normal(size=(COUNT, 4))
    return quats / np.linalg.norm(quats, axis=1, keepdims=True)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(39)


def test_quaternion_to_matrix_matches_the_formula(rng: np.random.Generator) -> None:
    for quat in _quaternions(rng):
        scaled = quat * rng.uniform(0.9, 1.1)
        np.testing.assert_allclose(
            rotations.quaternion_to_matrix(scaled), _quaternion_to_matrix(scaled), atol=ROUNDING
        )


def test_matrix_to_quaternion_matches_the_formula_with_non_negative_w(
    rng: np.random.Generator,
) -> None:
    quats = _quaternions(rng)
    quats[:10, 0] = 0.0  # half-turns: every branch of the old formula
    for quat in quats:
        matrix = _quaternion_to_matrix(quat)
        new = rotations.matrix_to_quaternion(matrix)
        assert new[0] >= 0.0
        if new[0] > 1e-6:  # at w = 0, q and -q are both right
            np.testing.assert_allclose(new, _matrix_to_quaternion(matrix), atol=ROUNDING)
        np.testing.assert_allclose(_quaternion_to_matrix(new), matrix, atol=ROUNDING)


def test_euler_angles_of_a_quaternion_match_the_formulas(rng: np.random.Generator) -> None:
    for quat in _quaternions(rng):
        assert rotations.yaw_of(quat) == pytest.approx(_yaw(quat), abs=ROUNDING)
        assert rotations.pitch_of(quat) == pytest.approx(_pitch(quat), abs=ROUNDING)
        assert rotations.roll_of(quat) == pytest.approx(_roll(quat), abs=ROUNDING)


def test_rpy_of_matrix_matches_the_formula(rng: np.random.Generator) -> None:
    angles = rng.uniform(-math.pi, math.pi, size=(COUNT, 3))
    angles[:, 1] /= 2.0
    angles[:20, 1] = np.pi / 2 - rng.uniform(1e-6, 1e-3, 20)  # near the pitch singularity
    for roll, pitch, yaw in angles:
        matrix = _matrix_of_rpy(roll, pitch, yaw)
        new = rotations.rpy_of_matrix(matrix)
        old = _rpy_of_matrix(matrix)
        # asin loses digits near +-pi/2 where Pinocchio's atan2 keeps them
        np.testing.assert_allclose(new, old, atol=1e-9 if abs(pitch) > 1.5 else ROUNDING)
        np.testing.assert_allclose(new, (roll, pitch, yaw), atol=1e-9)
        assert all(isinstance(angle, float) for angle in new)


def test_matrices_of_angles_match_the_formulas(rng: np.random.Generator) -> None:
    for roll, pitch, yaw in rng.uniform(-2 * math.pi, 2 * math.pi, size=(COUNT, 3)):
        np.testing.assert_allclose(
            rotations.matrix_of_rpy(roll, pitch, yaw),
            _matrix_of_rpy(roll, pitch, yaw),
            atol=ROUNDING,
        )
        np.testing.assert_allclose(rotations.rotation_z(yaw), _rotation_z(yaw), atol=ROUNDING)
        np.testing.assert_allclose(rotations.rotation_y(pitch), _rotation_y(pitch), atol=ROUNDING)


def test_skew_matches_the_formula(rng: np.random.Generator) -> None:
    for vector in rng.normal(size=(COUNT, 3)):
        np.testing.assert_array_equal(rotations.skew(vector), _skew(vector))
        np.testing.assert_allclose(rotations.skew(vector) @ vector, np.zeros(3), atol=ROUNDING)


@pytest.mark.parametrize(
    ("angle", "wrapped"),
    [(0.0, 0.0), (math.pi, -math.pi), (-math.pi, -math.pi), (3 * math.pi / 2, -math.pi / 2)],
)
def test_wrap_angle_is_into_minus_pi_to_pi(angle: float, wrapped: float) -> None:
    assert rotations.wrap_angle(angle) == pytest.approx(wrapped, abs=ROUNDING)


def test_euler_of_quaternions_is_the_logs_formulas_over_a_whole_log(
    rng: np.random.Generator,
) -> None:
    """Bit for bit the vectorised formulas of sim/metrics.py, sim/plots.py and
    boards/hovershoes/identify.py, and the scalar helpers' angles to rounding."""
    quats = _quaternions(rng).reshape(-1, 2, 4)
    w, x, y, z = (quats[..., i] for i in range(4))
    roll, pitch, yaw = rotations.euler_of_quaternions(quats)
    np.testing.assert_array_equal(
        roll, np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x**2 + y**2))
    )
    np.testing.assert_array_equal(pitch, np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0)))
    np.testing.assert_array_equal(
        yaw, np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    )
    for k, quat in enumerate(quats[:, 0]):
        assert rotations.roll_of(quat) == pytest.approx(roll[k, 0], abs=ROUNDING)
        assert rotations.pitch_of(quat) == pytest.approx(pitch[k, 0], abs=ROUNDING)
        assert rotations.yaw_of(quat) == pytest.approx(yaw[k, 0], abs=ROUNDING)


def _rodrigues(axis, angle):  # baselines/quadruped_skateboard.py, about a unit axis
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def test_exp3_matches_rodrigues_formula(rng: np.random.Generator) -> None:
    axes = rng.normal(size=(COUNT, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    for axis, angle in zip(axes, rng.uniform(0.0, math.pi, COUNT), strict=True):
        np.testing.assert_allclose(
            rotations.exp3(angle * axis), _rodrigues(axis, angle), atol=ROUNDING
        )
