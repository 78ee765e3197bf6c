"""MuJoCo body tree of a skateboard, built from its parameters.

Tree (every body named without prefix)::

    deck (free joint; box; site ``platform`` at the top surface centre, the IMU)
    ├── truck_front (hinge ``truck_front`` about the front kingpin axis)
    │   ├── wheel_fl (hinge about the axle)
    │   └── wheel_fr
    └── truck_rear  (hinge ``truck_rear`` about the rear kingpin axis)
        ├── wheel_rl
        └── wheel_rr

Each kingpin axis lies in the deck's x-z plane, passes through its axle centre and leans
from the deck normal by the rake :math:`\\gamma` toward the deck's nearer end (the pivot
cup sits outboard, as on a street truck), so its direction in the deck frame is
:math:`(\\pm\\sin\\gamma, 0, \\cos\\gamma)` (front, rear). With both wheels of a truck
on the ground, rolling the deck by :math:`\\varphi` turns the truck about its kingpin by
:math:`\\theta` with :math:`|\\tan\\theta| = |\\tan\\varphi| / \\sin\\gamma`, which yaws its
axle by :math:`\\delta` with :math:`\\tan\\delta = \\sin\\varphi \\cot\\gamma` (paper eq. 11):
the front axle steers into the lean and the rear axle out of it, so leaning right turns
right. Steering by leaning comes out of this geometry; nothing imposes it. The bushings
are the hinge's spring-damper (``stiffness``, ``damping``), bottoming out (the hinge
range) at the deck's roll limit.

Wheels collide as spheres (one contact point, no scrub while the truck steers) and are
drawn as cylinders; their bearings have a Coulomb rolling resistance (``frictionloss``)
and viscous damping. The skateboard has no electronics; the IMU on the platform and the
wheel and truck encoders are instruments for experiments and logs.
"""

from __future__ import annotations

import math

import mujoco

from ridempc.boards.skateboard.parameters import SkateboardParameters
from ridempc.mjcf import STIFF_CONTACT, add_encoder_sensors, add_imu_sensors

__all__ = [
    "DECK",
    "PLATFORM_SITE",
    "TRUCKS",
    "WHEELS",
    "build_skateboard",
    "kingpin_axis",
    "truck_limit",
]

DECK = "deck"
PLATFORM_SITE = "platform"
TRUCKS: tuple[str, str] = ("truck_front", "truck_rear")
WHEELS: tuple[tuple[str, str], tuple[str, str]] = (
    ("wheel_fl", "wheel_fr"),
    ("wheel_rl", "wheel_rr"),
)

_DECK_RGBA = [0.55, 0.36, 0.2, 1.0]
_GRIP_RGBA = [0.12, 0.12, 0.12, 1.0]
_TRUCK_RGBA = [0.7, 0.72, 0.75, 1.0]
_WHEEL_RGBA = [0.95, 0.85, 0.35, 1.0]
_HANGER_RADIUS = 0.008  # [m] axle capsule
_KINGPIN_RADIUS = 0.01  # [m] hanger arm along the kingpin axis
_BASEPLATE_HALF = (0.03, 0.035, 0.004)  # [m]
_COLLIDE = {"contype": 1, "conaffinity": 3, "condim": 3}
_VISUAL = {"contype": 0, "conaffinity": 0, "mass": 0.0, "group": 1}
_HIDDEN_GROUP = 3


def kingpin_axis(rake_deg: float, front: bool) -> tuple[float, float, float]:
    """Unit kingpin axis in the deck frame, from the axle up toward the deck's end.

    Args:
        rake_deg: Rake :math:`\\gamma`, angle of the axis from the deck normal [deg].
        front: Front truck (axis leans forward, toward the nose) or rear (toward the tail).
    """
    gamma = math.radians(rake_deg)
    sign = 1.0 if front else -1.0
    return (sign * math.sin(gamma), 0.0, math.cos(gamma))


def truck_limit(rake_deg: float, roll_limit: float) -> float:
    """Truck rotation about its kingpin at the deck's roll limit [rad].

    :math:`\\tan\\theta_{max} = \\tan\\varphi_{max} / \\sin\\gamma` (both wheels down).
    """
    return math.atan(math.tan(roll_limit) / math.sin(math.radians(rake_deg)))


def _add_truck(
    deck: mujoco.MjsBody,
    params: SkateboardParameters,
    name: str,
    wheels: tuple[str, str],
    front: bool,
    deck_centre_height: float,
) -> None:
    r = params.wheel_radius
    x = (0.5 if front else -0.5) * params.wheelbase
    truck = deck.add_body(name=name, pos=[x, 0.0, r - deck_centre_height])
    rake = params.rake_front if front else params.rake_rear
    axis = kingpin_axis(rake, front)
    limit = truck_limit(rake, params.roll_limit)
    truck.add_joint(
        name=name,
        type=mujoco.mjtJoint.mjJNT_HINGE,
        axis=list(axis),
        stiffness=params.bushing_stiffness,
        damping=params.bushing_damping,
        range=[-limit, limit],
        limited=mujoco.mjtLimited.mjLIMITED_TRUE,
    )
    # Hanger arm along the kingpin axis from the axle up to the baseplate under the deck.
    rise = params.height - params.deck_thickness - r - _BASEPLATE_HALF[2]
    top = [axis[0] * rise / axis[2], 0.0, rise]
    parts = params.truck_mass / 4.0  # axle, arm, baseplate share the truck's mass
    half_axle = 0.5 * params.track - 0.5 * params.wheel_width
    truck.add_geom(
        name=f"{name}_axle",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, -half_axle, 0.0, 0.0, half_axle, 0.0],
        size=[_HANGER_RADIUS, 0, 0],
        mass=parts,
        rgba=_TRUCK_RGBA,
        **_COLLIDE,
    )
    truck.add_geom(
        name=f"{name}_hanger",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.0, *top],
        size=[_KINGPIN_RADIUS, 0, 0],
        mass=parts,
        rgba=_TRUCK_RGBA,
        **_COLLIDE,
    )
    truck.add_geom(
        name=f"{name}_baseplate",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        pos=top,
        size=list(_BASEPLATE_HALF),
        mass=2.0 * parts,
        rgba=_TRUCK_RGBA,
        **_COLLIDE,
    )
    for side, wheel_name in zip((1.0, -1.0), wheels, strict=True):
        wheel = truck.add_body(name=wheel_name, pos=[0.0, side * 0.5 * params.track, 0.0])
        wheel.add_joint(
            name=wheel_name,
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=[0.0, 1.0, 0.0],
            frictionloss=params.wheel_friction_torque,
            damping=params.wheel_damping,
        )
        wheel.add_geom(
            name=wheel_name,
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[r, 0, 0],
            mass=params.wheel_mass,
            group=_HIDDEN_GROUP,
            rgba=_WHEEL_RGBA,
            **_COLLIDE,
        )
        wheel.add_geom(
            name=f"{wheel_name}_tyre",
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=[r, 0.5 * params.wheel_width, 0],
            quat=[math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0],
            rgba=_WHEEL_RGBA,
            **_VISUAL,
        )


def _add_sensors(spec: mujoco.MjSpec) -> None:
    add_imu_sensors(spec, PLATFORM_SITE, prefix="imu")
    for name in (*TRUCKS, *WHEELS[0], *WHEELS[1]):
        add_encoder_sensors(spec, name, f"{name}_pos", f"{name}_vel")


def build_skateboard(params: SkateboardParameters) -> mujoco.MjSpec:
    """The skateboard's own MuJoCo spec, resting on its wheels at the world origin.

    Args:
        params: The board's checked parameters.

    Returns:
        An uncompiled spec: the deck's top surface at ``params.height`` [m], the wheels
        touching z = 0, the ``platform`` site at the deck's top surface centre.
    """
    spec = mujoco.MjSpec()
    spec.modelname = params.name
    spec.compiler.degree = False
    half_t = 0.5 * params.deck_thickness
    centre_height = params.height - half_t
    deck = spec.worldbody.add_body(name=DECK, pos=[0.0, 0.0, centre_height])
    deck.add_freejoint(name=f"{DECK}_root")
    deck.add_geom(
        name=DECK,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.5 * params.deck_length, 0.5 * params.deck_width, half_t],
        mass=params.deck_mass,
        rgba=_DECK_RGBA,
        **_COLLIDE,
        **STIFF_CONTACT,
    )
    deck.add_geom(
        name=f"{DECK}_grip",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        pos=[0.0, 0.0, half_t],
        size=[0.5 * params.deck_length - 0.01, 0.5 * params.deck_width - 0.01, 0.0005],
        rgba=_GRIP_RGBA,
        **_VISUAL,
    )
    deck.add_site(name=PLATFORM_SITE, pos=[0.0, 0.0, half_t], size=[0.01, 0, 0], group=4)
    for truck, wheels, front in zip(TRUCKS, WHEELS, (True, False), strict=True):
        _add_truck(deck, params, truck, wheels, front, centre_height)
    for wheel in (*WHEELS[0], *WHEELS[1]):  # trucks and deck touch by parenthood already
        spec.add_exclude(bodyname1=DECK, bodyname2=wheel)
    _add_sensors(spec)
    return spec
