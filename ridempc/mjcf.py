"""Small MjSpec helpers shared by the scene builder and the board builders."""

from __future__ import annotations

import mujoco

__all__ = ["STIFF_CONTACT", "add_encoder_sensors", "add_imu_sensors"]

# The contact of a hard surface (floor, deck, platform, sole): stiffer than MuJoCo's default
# (time constant 0.02 s), so that a loaded foot sinks a millimetre, not a centimetre; the time
# constant stays above two physics steps (1.3 ms at 1500 Hz). MuJoCo averages the two geoms'
# solref and solimp, so both sides of a contact carry it.
STIFF_CONTACT: dict[str, list[float]] = {
    "solref": [0.005, 1.0],  # time constant [s], damping ratio
    "solimp": [0.95, 0.99, 0.001, 0.5, 2.0],  # impedance, width [m], shape
}

_IMU = (
    ("quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT),  # orientation (w, x, y, z)
    ("gyro", mujoco.mjtSensor.mjSENS_GYRO),  # [rad/s], site frame
    ("accel", mujoco.mjtSensor.mjSENS_ACCELEROMETER),  # specific force [m/s^2], site frame
)


def add_imu_sensors(spec: mujoco.MjSpec, site: str, prefix: str | None = None) -> None:
    """An IMU at ``site``: sensors ``<prefix>_quat``, ``<prefix>_gyro``, ``<prefix>_accel``.

    Args:
        spec: The spec to add to.
        site: The site the IMU is mounted at.
        prefix: Sensor name prefix (default: the site's name).
    """
    for suffix, kind in _IMU:
        spec.add_sensor(
            name=f"{prefix or site}_{suffix}",
            type=kind,
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=site,
        )


def add_encoder_sensors(spec: mujoco.MjSpec, joint: str, position: str, velocity: str) -> None:
    """A joint encoder: position [rad] and velocity [rad/s] sensors with the given names."""
    for name, kind in (
        (position, mujoco.mjtSensor.mjSENS_JOINTPOS),
        (velocity, mujoco.mjtSensor.mjSENS_JOINTVEL),
    ):
        spec.add_sensor(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_JOINT, objname=joint)
