"""A scene: the robot's description, the ground and (later) a board, compiled for MuJoCo.

The robot's MJCF stays untouched on disk; the scene builder edits a copy of its spec to
add the floor, light, the IMU's MuJoCo sensors and the physics options, and places the
robot in its standing keyframe with its lowest foot point ``FOOT_CLEARANCE`` above the
support, so the run starts settled (no interpenetration, no launch).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.robots.robot import Robot

__all__ = ["FOOT_CLEARANCE", "Scene", "build_scene"]

FOOT_CLEARANCE: float = 0.001  # [m] gap between the lowest foot point and the support at start
FLOOR_FRICTION: tuple[float, float, float] = (1.0, 0.005, 0.0001)  # slide, spin, roll
# A stiffer contact than MuJoCo's default (time constant 0.02 s), so feet sink millimetres,
# not centimetres; the time constant stays above two physics steps (1.3 ms at 1500 Hz).
GROUND_SOLREF: tuple[float, float] = (0.005, 1.0)  # time constant [s], damping ratio
GROUND_SOLIMP: tuple[float, ...] = (0.95, 0.99, 0.001, 0.5, 2.0)  # impedance, width [m], shape


@dataclass
class Scene:
    """A compiled scene and the indices the simulation needs.

    Attributes:
        model: Compiled MuJoCo model.
        data: Its data, in the initial state.
        robot: The rider.
        physics_hz: Physics rate [Hz].
        robot_qpos: The robot's slice of qpos.
        robot_qvel: The robot's slice of qvel.
        actuator_ids: Scene actuator ids of the robot's motors, motor order.
        base_body: Scene body id of the robot's base.
        robot_bodies: Body ids of the robot.
        foot_bodies: Body ids allowed to touch the support.
        ground_geoms: Geom ids of the ground.
        initial_qpos: The settled initial configuration.
    """

    model: mujoco.MjModel
    data: mujoco.MjData
    robot: Robot
    physics_hz: int
    robot_qpos: slice
    robot_qvel: slice
    actuator_ids: NDArray[np.int64]
    base_body: int
    robot_bodies: frozenset[int]
    foot_bodies: frozenset[int]
    ground_geoms: frozenset[int]
    initial_qpos: NDArray[np.float64]

    def reset(self) -> None:
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = self.initial_qpos
        mujoco.mj_forward(self.model, self.data)


def _add_world(spec: mujoco.MjSpec, physics_hz: int) -> None:
    spec.option.timestep = 1.0 / physics_hz
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.visual.global_.offwidth = 1280
    spec.visual.global_.offheight = 720
    spec.add_texture(
        name="sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=[0.55, 0.7, 0.9],
        rgb2=[0.1, 0.15, 0.25],
        width=256,
        height=256,
    )
    spec.add_texture(
        name="grid",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.25, 0.3, 0.35],
        rgb2=[0.35, 0.4, 0.45],
        width=512,
        height=512,
    )
    spec.add_material(name="grid", texrepeat=[1, 1], reflectance=0.1).textures[
        mujoco.mjtTextureRole.mjTEXROLE_RGB
    ] = "grid"
    spec.worldbody.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0, 0, 0.05],
        material="grid",
        contype=1,
        conaffinity=3,
        condim=3,
        friction=list(FLOOR_FRICTION),
        solref=list(GROUND_SOLREF),
        solimp=list(GROUND_SOLIMP),
    )
    spec.worldbody.add_light(
        name="sun", pos=[0, 0, 5], dir=[0, 0.2, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )


def _add_imu_sensors(spec: mujoco.MjSpec, imu_site: str) -> None:
    sensors = (
        ("quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT),
        ("gyro", mujoco.mjtSensor.mjSENS_GYRO),
        ("accel", mujoco.mjtSensor.mjSENS_ACCELEROMETER),
    )
    for suffix, kind in sensors:
        spec.add_sensor(
            name=f"{imu_site}_{suffix}",
            type=kind,
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=imu_site,
        )


def _geom_bottom(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> float:
    """Lowest world z of one geom [m]: exact for spheres, capsules, boxes and ellipsoids,
    the oriented bounding box otherwise."""
    kind = model.geom_type[geom]
    size = model.geom_size[geom]
    z = data.geom_xpos[geom, 2]
    up = data.geom_xmat[geom].reshape(3, 3)[2]  # world z in geom axes
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return float(z - size[0])
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        return float(z - abs(up[2]) * size[1] - size[0])
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return float(z - np.abs(up) @ size)
    if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return float(z - np.linalg.norm(up * size))
    center_local, half = model.geom_aabb[geom, :3], model.geom_aabb[geom, 3:]
    return float(z + up @ center_local - np.abs(up) @ half)


def _lowest_point(model: mujoco.MjModel, data: mujoco.MjData, bodies: frozenset[int]) -> float:
    """Lowest world z of the given bodies' collision geoms [m]."""
    bottoms = [
        _geom_bottom(model, data, g)
        for g in range(model.ngeom)
        if model.geom_bodyid[g] in bodies and model.geom_contype[g] != 0
    ]
    return min(bottoms)


def build_scene(robot: Robot, physics_hz: int) -> Scene:
    """Compile the robot standing on flat ground.

    Args:
        robot: The rider.
        physics_hz: Physics rate [Hz].
    """
    spec = robot.spec()
    for key in list(spec.keys):
        spec.delete(key)
    _add_world(spec, physics_hz)
    _add_imu_sensors(spec, robot.params.imu_site)
    model = spec.compile()
    data = mujoco.MjData(model)

    def body(name: str) -> int:
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)

    base = body(robot.params.base_body)
    robot_bodies = frozenset(b for b in range(1, model.nbody))
    feet = frozenset(body(name) for name in robot.params.foot_bodies)
    actuators = np.array(
        [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, m.name) for m in robot.motors]
    )
    qpos = robot.stand_qpos.copy()
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    qpos[2] += FOOT_CLEARANCE - _lowest_point(model, data, feet)
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    scene = Scene(
        model=model,
        data=data,
        robot=robot,
        physics_hz=physics_hz,
        robot_qpos=slice(0, robot.mj_model.nq),
        robot_qvel=slice(0, robot.mj_model.nv),
        actuator_ids=actuators,
        base_body=base,
        robot_bodies=robot_bodies,
        foot_bodies=feet,
        ground_geoms=frozenset({floor}),
        initial_qpos=qpos,
    )
    scene.reset()
    return scene
