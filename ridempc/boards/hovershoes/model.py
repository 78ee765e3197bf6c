"""MuJoCo description of a pair of Hovershoes, built from their parameters.

Each shoe is a free-floating platform body (its root) carrying a hub-motor wheel on a
hinge about the shoe's lateral axis (+y). The platform body's frame sits on the wheel axle,
with x forward, y to the left and z up; the foot deck is a box whose top surface carries
the platform site, where the rider's foot (or a dead weight) stands.

Per shoe ``s`` in (``left``, ``right``) the board has:

- bodies: the platform (``params.platform_sites`` tell the site names, ``params.ground_bodies``
  the wheel body names, in the order left, right), its free joint ``<s>_shoe_root``;
- the wheel hinge ``<s>_wheel`` and its motor ``<s>_wheel`` (gear 1, ctrlrange = the motor
  torque limit [N m]);
- sensors: ``<s>_imu_quat`` (frame quaternion), ``<s>_imu_gyro`` [rad/s], ``<s>_imu_accel``
  [m/s^2] on the IMU site in the deck, ``<s>_wheel_angle`` [rad] and ``<s>_wheel_speed``
  [rad/s] (wheel encoder, relative to the platform).

The wheel is a flat cylinder as wide as ``wheel_width``: MuJoCo's cylinder-plane contact
puts a contact at each rim, so the tyre carries the shoe sideways (no lateral sliding, a
loaded shoe does not roll over on its own) and resists yaw by friction at its rims, while it
rolls freely forward. On the terrain the tyre touches as a capsule of the same radius and
rim points, ``<s>_tread`` (:mod:`ridempc.terrain_contact`: MuJoCo's cylinder-box collider
gets an edge wrong). Inertias are explicit, so MuJoCo and Pinocchio read the same masses.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ridempc.boards.hovershoes.parameters import HovershoesParameters
from ridempc.boards.parameters import BoardParameters
from ridempc.mjcf import STIFF_CONTACT, add_encoder_sensors, add_imu_sensors
from ridempc.terrain_contact import TREAD_BITS, WHEEL_ON_FLOOR_BITS

__all__ = ["SIDES", "build_hovershoes", "shoe_names"]

SIDES: tuple[str, str] = ("left", "right")
_BOARD = {"contype": 1, "conaffinity": 3, "condim": 3}  # touches the ground and the rider
_VISUAL = {"contype": 0, "conaffinity": 0, "group": 1}
_Y_AXIS_QUAT = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # geom z onto body y
_WHEEL_DAMPING = 0.002  # [N m s / rad] hub bearing and motor losses (estimate)
_TREAD_COLOUR = [0.12, 0.12, 0.12, 1.0]
_SHELL_COLOUR = [0.85, 0.85, 0.88, 1.0]
_PAD_COLOUR = [0.2, 0.25, 0.3, 1.0]


def shoe_names(side: str) -> dict[str, str]:
    """Element names of one shoe (``left`` or ``right``), sensors and actuator included."""
    return {
        "root": f"{side}_shoe_root",
        "imu": f"{side}_imu",
        "quat": f"{side}_imu_quat",
        "gyro": f"{side}_imu_gyro",
        "accel": f"{side}_imu_accel",
        "wheel_joint": f"{side}_wheel",
        "motor": f"{side}_wheel",
        "wheel_angle": f"{side}_wheel_angle",
        "wheel_speed": f"{side}_wheel_speed",
    }


def _box_inertia(mass: float, size: tuple[float, float, float]) -> list[float]:
    """Principal inertia of a solid box of full size (lx, ly, lz) [kg m^2]."""
    lx, ly, lz = size
    return [
        mass * (ly**2 + lz**2) / 12.0,
        mass * (lx**2 + lz**2) / 12.0,
        mass * (lx**2 + ly**2) / 12.0,
    ]


def _add_shoe(spec: mujoco.MjSpec, p: HovershoesParameters, index: int, y: float) -> None:
    side = SIDES[index]
    names = shoe_names(side)
    radius = p.wheel_radius
    deck_top = p.platform_height - radius  # in the platform frame (origin on the axle)
    deck_centre = deck_top - 0.5 * p.platform_thickness
    shoe = spec.worldbody.add_body(name=f"{side}_shoe", pos=[0.0, y, radius])
    shoe.add_freejoint(name=names["root"])
    # The shell, battery, electronics, deck and the motor's stator: one rigid body whose mass
    # spreads from the bottom of the wheel to the deck top, as a solid box that size.
    body_mass = p.shoe_mass - p.wheel_mass
    shell_height = deck_top + radius
    shoe.explicitinertial = True
    shoe.mass = body_mass
    shoe.ipos = [0.0, 0.0, 0.5 * (deck_top - radius)]
    shoe.inertia = _box_inertia(body_mass, (p.platform_length, p.platform_width, shell_height))
    half = [0.5 * p.platform_length, 0.5 * p.platform_width, 0.5 * p.platform_thickness]
    shoe.add_geom(
        name=f"{side}_deck",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=half,
        pos=[0.0, 0.0, deck_centre],
        friction=[p.platform_friction, 0.005, 0.0001],
        rgba=_PAD_COLOUR,
        **_BOARD,
        **STIFF_CONTACT,
    )
    # The shell in front of and behind the wheel (drawn only, it never touches anything).
    shell_half = [0.5 * p.platform_length * 0.9, 0.5 * p.platform_width * 0.95]
    shell_bottom = 0.45 * radius - radius  # keep the drawn shell off the ground
    shell_top = deck_top - p.platform_thickness
    for sign in (1.0, -1.0):
        shoe.add_geom(
            name=f"{side}_shell_{'front' if sign > 0 else 'back'}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[
                0.5 * (shell_half[0] - radius * 1.1),
                shell_half[1],
                0.5 * (shell_top - shell_bottom),
            ],
            pos=[
                sign * 0.5 * (shell_half[0] + radius * 1.1),
                0.0,
                0.5 * (shell_top + shell_bottom),
            ],
            rgba=_SHELL_COLOUR,
            **_VISUAL,
        )
    shoe.add_site(name=p.platform_sites[index], pos=[0.0, 0.0, deck_top], size=[0.01] * 3)
    shoe.add_site(name=names["imu"], pos=[0.0, 0.0, deck_centre], size=[0.008] * 3)

    wheel = shoe.add_body(name=p.ground_bodies[index], pos=[0.0, 0.0, 0.0])
    wheel.explicitinertial = True
    wheel.mass = p.wheel_mass
    wheel.ipos = [0.0, 0.0, 0.0]  # set, or MjSpec.to_xml drops the <inertial> element
    axial = 0.5 * p.wheel_mass * radius**2  # hub-motor rotor and tyre as a solid cylinder
    diametral = p.wheel_mass * (3.0 * radius**2 + p.wheel_width**2) / 12.0
    wheel.inertia = [diametral, axial, diametral]
    wheel.add_joint(
        name=names["wheel_joint"],
        type=mujoco.mjtJoint.mjJNT_HINGE,
        axis=[0.0, 1.0, 0.0],
        damping=_WHEEL_DAMPING,
    )
    # The tyre, a cylinder on the floor plane; on the terrain a capsule with the same rim
    # points (the tread, not drawn): MuJoCo's cylinder-box collider puts an edge's contact on
    # the box's side face (ridempc.terrain_contact).
    tyre = {"size": [radius, 0.5 * p.wheel_width, 0.0], "quat": _Y_AXIS_QUAT, "rgba": _TREAD_COLOUR}
    for name, kind, bits in (
        ("tyre", mujoco.mjtGeom.mjGEOM_CYLINDER, {**_BOARD, **WHEEL_ON_FLOOR_BITS}),
        ("tread", mujoco.mjtGeom.mjGEOM_CAPSULE, {**_BOARD, **TREAD_BITS, "group": 3}),
    ):
        wheel.add_geom(name=f"{side}_{name}", type=kind, **tyre, **bits)
    wheel.add_geom(  # a hub mark, to see the wheel turn
        name=f"{side}_hub_mark",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.7 * radius, 0.5 * p.wheel_width + 0.002, 0.1 * radius],
        rgba=[0.9, 0.5, 0.1, 1.0],
        **_VISUAL,
    )

    spec.add_actuator(
        name=names["motor"],
        target=names["wheel_joint"],
        trntype=mujoco.mjtTrn.mjTRN_JOINT,
        gear=[1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ctrllimited=True,
        ctrlrange=[-p.motor_torque_limit, p.motor_torque_limit],
    )  # a <motor>: unit gain, no bias (MjSpec writes it as the equivalent <general>)
    add_imu_sensors(spec, names["imu"])
    add_encoder_sensors(spec, names["wheel_joint"], names["wheel_angle"], names["wheel_speed"])


def build_hovershoes(params: BoardParameters) -> mujoco.MjSpec:
    """The pair's MuJoCo spec: both shoes resting upright on z = 0, left at +y.

    Args:
        params: A pair's checked parameters.

    Returns:
        The spec, unprefixed, with no world options (the scene sets them).
    """
    assert isinstance(params, HovershoesParameters)
    spec = mujoco.MjSpec()
    spec.modelname = params.name
    for index in range(len(SIDES)):
        _add_shoe(spec, params, index, (0.5 - index) * params.shoe_spacing)
    return spec
