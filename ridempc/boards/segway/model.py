"""The Segway's MuJoCo description, built from its parameters.

Bodies (all names unprefixed; the scene attaches them under ``board/``):

- ``chassis`` (free root, frame origin at the middle of the axle): the foot platform, a box
  whose top surface carries the site ``platform`` and the IMU (``platform_quat``,
  ``platform_gyro``, ``platform_accel``);
- ``left_wheel`` / ``right_wheel`` on hinges ``left_wheel_spin`` / ``right_wheel_spin`` about
  the axle (+y; positive spin rolls the board forward), driven by the motors ``left_wheel`` /
  ``right_wheel`` (``ctrlrange`` = torque limit), with encoders ``<side>_wheel_pos`` and
  ``<side>_wheel_vel``;
- ``knee_bar``: a column rising from the platform centre with a knee pad, on the hinge
  ``knee_bar_hinge`` about -x at the platform top, so that a positive angle (sensor
  ``knee_bar_angle``) is the bar pushed to the left (+y); a centring spring holds it upright.

Each body carries an explicit inertial (computed by MuJoCo from its primitive geoms), so that
MuJoCo and Pinocchio read the same masses; purely visual geoms have no mass.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ridempc.boards.parameters import BoardParameters
from ridempc.boards.segway.parameters import SegwayParameters
from ridempc.errors import ConfigError
from ridempc.mjcf import add_imu_sensors

__all__ = ["build_segway", "wheel_sides"]

BOARD_BITS = {"contype": 1, "conaffinity": 3}  # touches the ground and the rider
VISUAL_BITS = {"contype": 0, "conaffinity": 0, "group": 1, "density": 0.0}
AXLE_QUAT = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # cylinder axis z -> y
TYRE_FRICTION = [1.0, 0.005, 0.0001]
WHEEL_DAMPING: float = 0.02  # [N m s / rad] bearing and motor drag


def wheel_sides() -> tuple[tuple[str, float], ...]:
    """The wheels by side and the sign of their y position (left = +y)."""
    return (("left", 1.0), ("right", -1.0))


def _add_chassis(spec: mujoco.MjSpec, p: SegwayParameters) -> mujoco.MjsBody:
    chassis = spec.worldbody.add_body(name="chassis", pos=[0.0, 0.0, p.wheel_radius])
    chassis.add_freejoint(name="chassis_root")
    top = p.platform_height - p.wheel_radius  # platform top over the axle [m]
    chassis.add_geom(
        name="platform",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[p.platform_length / 2, p.platform_width / 2, p.platform_thickness / 2],
        pos=[0.0, 0.0, top - p.platform_thickness / 2],
        mass=p.chassis_mass,
        rgba=[0.2, 0.22, 0.25, 1.0],
        friction=TYRE_FRICTION,
        **BOARD_BITS,
    )
    for side, sign in wheel_sides():  # fenders, for the eye only
        chassis.add_geom(
            name=f"{side}_fender",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[p.wheel_radius * 0.8, p.wheel_width / 2 + 0.005, 0.006],
            pos=[0.0, sign * p.track_width / 2, p.wheel_radius + 0.012],
            rgba=[0.9, 0.9, 0.92, 1.0],
            **VISUAL_BITS,
        )
    chassis.add_site(name="platform", pos=[0.0, 0.0, top], size=[0.01, 0.01, 0.01])
    return chassis


def _add_wheels(spec: mujoco.MjSpec, chassis: mujoco.MjsBody, p: SegwayParameters) -> None:
    for side, sign in wheel_sides():
        wheel = chassis.add_body(name=f"{side}_wheel", pos=[0.0, sign * p.track_width / 2, 0.0])
        wheel.add_joint(
            name=f"{side}_wheel_spin",
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=[0.0, 1.0, 0.0],
            damping=WHEEL_DAMPING,
        )
        wheel.add_geom(  # a rounded tyre: one contact point, as a pneumatic tyre's small patch
            name=f"{side}_tyre",
            type=mujoco.mjtGeom.mjGEOM_ELLIPSOID,
            size=[p.wheel_radius, p.wheel_radius, p.wheel_width / 2],
            quat=AXLE_QUAT,
            mass=p.wheel_mass,
            rgba=[0.08, 0.08, 0.08, 1.0],
            friction=TYRE_FRICTION,
            condim=3,
            **BOARD_BITS,
        )
        wheel.add_geom(
            name=f"{side}_rim",
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=[p.wheel_radius * 0.97, p.wheel_width / 2, 0.0],
            quat=AXLE_QUAT,
            rgba=[0.12, 0.12, 0.12, 1.0],
            **VISUAL_BITS,
        )
        wheel.add_geom(  # a spoke, so that the wheel's turning shows in videos
            name=f"{side}_spoke",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[p.wheel_radius * 0.85, p.wheel_width / 2 + 0.002, 0.015],
            rgba=[0.85, 0.45, 0.1, 1.0],
            **VISUAL_BITS,
        )
        spec.add_actuator(
            name=f"{side}_wheel",
            target=f"{side}_wheel_spin",
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gainprm=[1.0] + [0.0] * 9,
            ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
            ctrlrange=[-p.motor_torque_limit, p.motor_torque_limit],
        )
        for suffix, kind in (
            ("pos", mujoco.mjtSensor.mjSENS_JOINTPOS),
            ("vel", mujoco.mjtSensor.mjSENS_JOINTVEL),
        ):
            spec.add_sensor(
                name=f"{side}_wheel_{suffix}",
                type=kind,
                objtype=mujoco.mjtObj.mjOBJ_JOINT,
                objname=f"{side}_wheel_spin",
            )


def _add_knee_bar(spec: mujoco.MjSpec, chassis: mujoco.MjsBody, p: SegwayParameters) -> None:
    top = p.platform_height - p.wheel_radius
    bar = chassis.add_body(name="knee_bar", pos=[0.0, 0.0, top])
    bar.add_joint(
        name="knee_bar_hinge",
        type=mujoco.mjtJoint.mjJNT_HINGE,
        axis=[-1.0, 0.0, 0.0],  # positive = bar pushed to the left (+y)
        stiffness=p.knee_bar_stiffness,
        damping=p.knee_bar_damping,
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
        range=[-np.radians(p.knee_bar_range), np.radians(p.knee_bar_range)],
    )
    column_top = p.knee_bar_height - p.knee_pad_height / 2
    column_mass = 0.6 * p.knee_bar_mass
    lower = p.knee_bar_contact_from
    bar.add_geom(
        name="knee_bar_foot",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.0, 0.0, 0.0, max(lower, 1e-3)],
        size=[p.knee_bar_radius, 0.0, 0.0],
        mass=column_mass * lower / column_top,
        rgba=[0.6, 0.62, 0.65, 1.0],
        contype=0,
        conaffinity=0,
        group=1,
    )
    bar.add_geom(
        name="knee_bar_column",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, lower, 0.0, 0.0, column_top],
        size=[p.knee_bar_radius, 0.0, 0.0],
        mass=column_mass * (column_top - lower) / column_top,
        rgba=[0.6, 0.62, 0.65, 1.0],
        **BOARD_BITS,
    )
    bar.add_geom(
        name="knee_pad",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[p.knee_pad_depth / 2, p.knee_pad_width / 2, p.knee_pad_height / 2],
        pos=[0.0, 0.0, p.knee_bar_height],
        mass=p.knee_bar_mass - column_mass,
        rgba=[0.85, 0.45, 0.1, 1.0],
        **BOARD_BITS,
    )
    for suffix, kind in (
        ("angle", mujoco.mjtSensor.mjSENS_JOINTPOS),
        ("rate", mujoco.mjtSensor.mjSENS_JOINTVEL),
    ):
        spec.add_sensor(
            name=f"knee_bar_{suffix}",
            type=kind,
            objtype=mujoco.mjtObj.mjOBJ_JOINT,
            objname="knee_bar_hinge",
        )
    for side, _ in wheel_sides():
        spec.add_exclude(bodyname1="knee_bar", bodyname2=f"{side}_wheel")


def _add_imu(spec: mujoco.MjSpec) -> None:
    add_imu_sensors(spec, "platform")


def _freeze_inertials(spec: mujoco.MjSpec) -> None:
    """Write each body's compiled inertia as an explicit inertial (what Pinocchio reads)."""
    model = spec.compile()
    for body in spec.bodies[1:]:
        i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body.name)
        body.explicitinertial = True
        body.mass = float(model.body_mass[i])
        body.ipos = model.body_ipos[i].copy()
        body.iquat = model.body_iquat[i].copy()
        body.inertia = model.body_inertia[i].copy()


def build_segway(params: BoardParameters) -> mujoco.MjSpec:
    """The Segway resting on level ground at the origin, wheels touching z = 0.

    Args:
        params: The board's :class:`SegwayParameters`.

    Returns:
        Its own spec (unprefixed), with the platform site at the platform's top centre.
    """
    if not isinstance(params, SegwayParameters):
        raise ConfigError(f"board '{params.name}': not a Segway's parameters")
    spec = mujoco.MjSpec()
    spec.modelname = params.name
    spec.compiler.degree = False  # every angle below is in radians
    chassis = _add_chassis(spec, params)
    _add_wheels(spec, chassis, params)
    _add_knee_bar(spec, chassis, params)
    _add_imu(spec)
    _freeze_inertials(spec)
    return spec
