"""A scene: the robot's description, the ground and (later) a board, compiled for MuJoCo.

The robot's MJCF stays untouched on disk; the scene builder edits a copy of its spec to
add the floor, light, the IMU's MuJoCo sensors and the physics options, and places the
robot in its standing keyframe with its lowest foot point ``FOOT_CLEARANCE`` above the
support, so the run starts settled (no interpenetration, no launch). The floor's and the
decks' contacts are explicit pairs (:mod:`ridempc.sim.contact_pairs`), so that a scenario
can change their friction.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.errors import ConfigError
from ridempc.mjcf import STIFF_CONTACT, add_imu_sensors
from ridempc.robots.robot import Robot
from ridempc.sim.contact_pairs import add_surface_pairs, collision_geoms

if TYPE_CHECKING:  # the terrain reads the scenarios, whose knobs read this module
    from ridempc.sim.terrain import TerrainLayout

__all__ = ["BOARD_PREFIX", "FOOT_CLEARANCE", "Scene", "build_scene"]

FOOT_CLEARANCE: float = 0.001  # [m] gap between the lowest foot point and the support at start
FLOOR_FRICTION: tuple[float, float, float] = (1.0, 0.005, 0.0001)  # slide, spin, roll
# MuJoCo's soft contacts let a loaded foot creep down a tilted or turning platform (the
# constraint force only builds up with slip velocity). Noslip iterations project the
# friction forces back inside the cone after the main solve, so a standing foot holds.
NOSLIP_ITERATIONS: int = 10


BOARD_PREFIX = "board/"
DEAD_WEIGHT_DENSITY: float = 7800.0  # [kg / m^3] steel
DEAD_WEIGHT_HALF_FOOTPRINT: tuple[float, float] = (0.08, 0.06)  # [m] per platform


@dataclass
class Scene:
    """A compiled scene and the indices the simulation needs.

    Attributes:
        model: Compiled MuJoCo model.
        data: Its data, in the initial state.
        robot: The rider, or None when a dead weight rides.
        board: The board, or None for flat ground.
        physics_hz: Physics rate [Hz].
        robot_qpos: The robot's slice of qpos (empty without a robot).
        robot_qvel: The robot's slice of qvel (empty without a robot).
        actuator_ids: Scene actuator ids of the robot's motors, motor order.
        base_body: Body id of the rider's base (robot base, or the first dead weight).
        rider_mass: Mass of the rider [kg].
        rider_bodies: Body ids of the rider (robot or dead weights).
        foot_bodies: Rider bodies allowed to touch the ground (none for a dead weight).
        board_bodies: Body ids of the board.
        board_roots: Board bodies carrying a free joint (one per independent platform).
        board_ground_bodies: Board bodies allowed to touch the ground (wheels).
        ground_geoms: Geom ids of the ground.
        deck_geoms: Collision geom ids of the board's platforms (where the rider stands).
        support_height: Height of the rider's support at the start [m] (platform top or 0).
        initial_qpos: The settled initial configuration.
        terrain: The scenario's terrain (the judge's ground heights), or None: flat ground.
    """

    model: mujoco.MjModel
    data: mujoco.MjData
    robot: Robot | None
    board: Board | None
    physics_hz: int
    robot_qpos: slice
    robot_qvel: slice
    actuator_ids: NDArray[np.int64]
    base_body: int
    rider_mass: float
    rider_bodies: frozenset[int]
    foot_bodies: frozenset[int]
    board_bodies: frozenset[int]
    board_roots: tuple[int, ...]
    board_ground_bodies: frozenset[int]
    ground_geoms: frozenset[int]
    support_height: float
    initial_qpos: NDArray[np.float64]
    deck_geoms: frozenset[int] = frozenset()
    terrain: TerrainLayout | None = None

    def reset(self) -> None:
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = self.initial_qpos
        mujoco.mj_forward(self.model, self.data)

    def body_id(self, name: str) -> int:
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)


def _add_world(spec: mujoco.MjSpec, physics_hz: int) -> None:
    spec.option.timestep = 1.0 / physics_hz
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.noslip_iterations = NOSLIP_ITERATIONS
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
        **STIFF_CONTACT,
    )
    spec.worldbody.add_light(
        name="sun", pos=[0, 0, 5], dir=[0, 0.2, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
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


def _free_root(model: mujoco.MjModel, body: int) -> int:
    """The ancestor of ``body`` that carries a free joint."""
    while body > 0:
        adr = model.body_jntadr[body]
        if adr >= 0 and model.jnt_type[adr] == mujoco.mjtJoint.mjJNT_FREE:
            return body
        body = int(model.body_parentid[body])
    raise ConfigError("a platform site is not on a free-floating board body")


def _add_dead_weights(
    spec: mujoco.MjSpec, mass: float, count: int, half_footprint: tuple[float, float]
) -> list[str]:
    """Steel boxes of ``mass / count`` each, one per platform, that only rest there by friction."""
    each = mass / count
    hx, hy = half_footprint
    hz = each / (DEAD_WEIGHT_DENSITY * 8.0 * hx * hy)
    names = []
    for i in range(count):
        name = f"dead_weight_{i}"
        body = spec.worldbody.add_body(name=name, pos=[0.0, 0.0, 1.0 + i])
        body.add_freejoint(name=f"{name}_root")
        body.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[hx, hy, hz],
            mass=each,
            contype=2,
            conaffinity=1,
            condim=3,
            rgba=[0.6, 0.6, 0.65, 1.0],
        )
        names.append(name)
    return names


def build_scene(
    robot: Robot | None,
    physics_hz: int,
    board: Board | None = None,
    dead_weight: float | None = None,
    foot_offset: tuple[float, float] = (0.0, 0.0),
    platform_offsets: tuple[tuple[float, float], ...] = (),
    terrain: TerrainLayout | None = None,
    edit_spec: Callable[[mujoco.MjSpec], None] | None = None,
) -> Scene:
    """Compile a rider on a board (or on flat ground) in a settled initial state.

    Args:
        robot: The rider, or None for a dead weight.
        physics_hz: Physics rate [Hz].
        board: The board, or None for flat ground.
        dead_weight: Mass of the dead weight when ``robot`` is None [kg].
        foot_offset: Feet (or weight) offset from the platform centre, (x, y) [m].
        platform_offsets: Per independent platform, a further shift of that platform, (x, y)
            [m] (Hovershoes started staggered).
        terrain: The scenario's terrain (:func:`ridempc.sim.terrain.lay_out`), or None.
        edit_spec: Called with the model spec before it is compiled, to add to the scene
            (a course's obstacles, a camera on the rider).

    The rider's feet go over the board's platform site(s): a rigid board puts the centroid
    of all feet over its one platform; independent platforms (Hovershoes) each move under
    their foot. The lowest foot point starts ``FOOT_CLEARANCE`` above the support.
    """
    if robot is None and (dead_weight is None or dead_weight <= 0.0):
        raise ConfigError("a scene without a robot needs a positive dead-weight mass")
    spec = robot.spec() if robot is not None else mujoco.MjSpec()
    for key in list(spec.keys):
        spec.delete(key)
    _add_world(spec, physics_hz)
    terrain_names = []
    if terrain is not None:
        from ridempc.sim.terrain import add_terrain

        terrain_names = add_terrain(spec, terrain)
    if edit_spec is not None:
        edit_spec(spec)
    if robot is not None:
        add_imu_sensors(spec, robot.params.imu_site)
        rider_names = [robot.params.base_body]
    platforms = board.params.platform_sites if board is not None else ()
    if robot is None:
        assert dead_weight is not None
        footprint = DEAD_WEIGHT_HALF_FOOTPRINT if len(platforms) > 1 else (0.12, 0.09)
        rider_names = _add_dead_weights(spec, dead_weight, max(1, len(platforms)), footprint)
    if board is not None:
        spec.attach(board.spec(), prefix=BOARD_PREFIX, frame=spec.worldbody.add_frame())
    model = spec.compile()
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    ground = [floor] + [
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in terrain_names
    ]
    decks = _deck_geoms(model, board)
    model = add_surface_pairs(spec, model, [*ground, *decks])  # for friction changes
    data = mujoco.MjData(model)

    def body(name: str) -> int:
        found = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        if found < 0:
            raise ConfigError(f"scene has no body '{name}'")
        return found

    n_robot_q = robot.mj_model.nq if robot is not None else 0
    n_robot_v = robot.mj_model.nv if robot is not None else 0
    if robot is not None:
        base = body(robot.params.base_body)
        feet = [body(name) for name in robot.params.foot_bodies]
        rider_bodies = frozenset(
            b for b in range(1, model.nbody) if model.body_rootid[b] == model.body_rootid[base]
        )
        rider_mass = robot.mass
        actuators = np.array(
            [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, m.name) for m in robot.motors]
        )
    else:
        feet = [body(name) for name in rider_names]
        base = feet[0]
        rider_bodies = frozenset(feet)
        rider_mass = float(dead_weight or 0.0)
        actuators = np.zeros(0, dtype=int)

    qpos = model.qpos0.copy()
    if robot is not None:
        qpos[:n_robot_q] = robot.stance_qpos(board.name if board is not None else "none")
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)

    board_bodies: frozenset[int] = frozenset()
    board_roots: tuple[int, ...] = ()
    board_ground: frozenset[int] = frozenset()
    support = 0.0
    if board is not None:
        board_bodies = frozenset(
            b
            for b in range(1, model.nbody)
            if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or "").startswith(
                BOARD_PREFIX
            )
        )
        board_ground = frozenset(body(BOARD_PREFIX + n) for n in board.params.ground_bodies)
        sites = [
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, BOARD_PREFIX + n) for n in platforms
        ]
        if min(sites) < 0:
            raise ConfigError(f"board '{board.name}': a platform site is missing from its model")
        roots = [_free_root(model, int(model.site_bodyid[s])) for s in sites]
        board_roots = tuple(dict.fromkeys(roots))
        foot_xy = [_body_footprint_center(model, data, b) for b in feet]
        offset = np.asarray(foot_offset)
        if robot is None:  # each weight onto its platform
            for site, weight in zip(sites, feet, strict=True):
                _shift_root(
                    model, qpos, weight, data.site_xpos[site, :2] + offset - data.xpos[weight, :2]
                )
        elif len(sites) == 1:  # a rigid board: the feet's centroid over its platform
            shift = data.site_xpos[sites[0], :2] + offset - np.mean(foot_xy, axis=0)
            _shift_root(model, qpos, base, shift)
        elif len(sites) == len(feet):  # independent platforms, each under its foot
            shifts = list(platform_offsets) or [(0.0, 0.0)] * len(sites)
            if len(shifts) != len(sites):
                raise ConfigError(
                    f"{len(shifts)} platform offsets for {len(sites)} platforms of '{board.name}'"
                )
            for site, root, xy, extra in zip(sites, roots, foot_xy, shifts, strict=True):
                target = xy - offset + np.asarray(extra)
                _shift_root(model, qpos, root, target - data.site_xpos[site, :2])
        else:
            raise ConfigError(
                f"board '{board.name}' has {len(sites)} platforms; the rider has {len(feet)} feet"
            )
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        support = float(max(data.site_xpos[s, 2] for s in sites))
    for root in sorted({int(model.body_rootid[b]) for b in feet}):
        lowest = _lowest_point(
            model, data, frozenset(b for b in feet if model.body_rootid[b] == root)
        )
        _shift_root(model, qpos, root, np.zeros(2), support + FOOT_CLEARANCE - lowest)
    if board is not None and robot is not None:
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        _check_feet_over(model, data, robot, board, frozenset(board_bodies))
    scene = Scene(
        model=model,
        data=data,
        robot=robot,
        board=board,
        physics_hz=physics_hz,
        robot_qpos=slice(0, n_robot_q),
        robot_qvel=slice(0, n_robot_v),
        actuator_ids=actuators,
        base_body=base,
        rider_mass=rider_mass,
        rider_bodies=rider_bodies,
        foot_bodies=frozenset(feet) if robot is not None else frozenset(),
        board_bodies=board_bodies,
        board_roots=board_roots,
        board_ground_bodies=board_ground,
        ground_geoms=frozenset(ground),
        deck_geoms=frozenset(decks),
        support_height=support,
        initial_qpos=qpos,
        terrain=terrain,
    )
    scene.reset()
    return scene


def _deck_geoms(model: mujoco.MjModel, board: Board | None) -> list[int]:
    """Collision geoms of the bodies carrying the board's platform sites."""
    if board is None:
        return []
    sites = [
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, BOARD_PREFIX + n)
        for n in board.params.platform_sites
    ]
    bodies = {int(model.site_bodyid[s]) for s in sites if s >= 0}  # a missing one: refused later
    return sorted(collision_geoms(model, bodies))


def _check_feet_over(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    robot: Robot,
    board: Board,
    board_bodies: frozenset[int],
) -> None:
    """Every contact point must have the board right below it (a ray cast straight down)."""
    down = np.array([0.0, 0.0, -1.0])
    hit = np.zeros(1, dtype=np.int32)
    for name in robot.params.contact_sites:
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
        start = data.site_xpos[site] + np.array([0.0, 0.0, 0.005])
        distance = mujoco.mj_ray(model, data, start, down, None, True, model.site_bodyid[site], hit)
        if distance < 0 or distance > 0.05 or model.geom_bodyid[hit[0]] not in board_bodies:
            raise ConfigError(
                f"{robot.name} does not fit on board '{board.name}': contact point '{name}' "
                "is not over the platform"
            )


def _body_footprint_center(model: mujoco.MjModel, data: mujoco.MjData, body: int) -> np.ndarray:
    """Horizontal centre of a body's collision geoms [m]."""
    geoms = [
        g for g in range(model.ngeom) if model.geom_bodyid[g] == body and model.geom_contype[g]
    ]
    points = [data.geom_xpos[g, :2] for g in geoms] or [data.xpos[body, :2]]
    return np.mean(points, axis=0)


def _shift_root(
    model: mujoco.MjModel, qpos: np.ndarray, body: int, xy: np.ndarray, z: float = 0.0
) -> None:
    """Translate a free-floating body tree (by its root's free joint) in the world [m]."""
    root = int(model.body_rootid[body])
    adr = model.jnt_qposadr[model.body_jntadr[root]]
    qpos[adr : adr + 2] += xy
    qpos[adr + 2] += z
