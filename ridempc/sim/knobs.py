"""The knobs a scenario's ``[[changes]]`` can turn: for each, its unit, range, where it
applies and how (:data:`KNOBS`).

- ``floor_friction``, ``tyre_friction``, ``deck_friction`` [-]: the sliding friction of the
  floor, the wheels' and the platforms' collision geoms; the floor's and the decks' contacts
  are explicit pairs whose friction follows the product rule (:mod:`ridempc.sim.contact_pairs`);
- ``board_mass`` [kg] (``body``): one board body's mass, its inertia scaled with it;
- ``wheel_radius`` [m], ``bushing_stiffness`` [N m/rad], ``bushing_damping`` [N m s/rad],
  ``firmware_gain`` (``gain``): a field of the board's parameters, checked by the board's own
  parameter model; the board's builder says what follows (:mod:`ridempc.sim.board_edits`:
  tyre size, wheel inertia, the axle under a deck that keeps its height, joint springs), and
  the firmware runs on the new parameters (its speed estimate uses the new radius); the
  Hovershoes' deck clears its wheel by 1 mm, so their parameter model refuses a larger one;
- ``payload`` (``body``, ``mass`` [kg], ``offset`` [m] in the body frame): a point mass on
  a rider body (``base`` for the base), its mass, centre of mass and inertia updated; a
  negative mass is a lighter rider: every body of the named body's subtree (``base``: the
  whole rider) has its mass and inertia scaled by :math:`(M + m)/M`, :math:`M` the
  subtree's mass, each centre of mass kept (the ``offset`` does not apply), and ``-m``
  must stay below :math:`M`;
  ``base_payload`` [kg]: one at the base's centre of mass;
- ``motor_torque_limit`` (``scale`` only): every robot motor's peak torque;
- ``joint_damping`` [N m s/rad] (``joint``, else every robot joint): the robot joints'
  damping.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np
from numpy.typing import NDArray
from pydantic import ValidationError

from ridempc.boards.parameters import BoardParameters
from ridempc.sim.board_edits import board_edits
from ridempc.sim.contact_pairs import collision_geoms
from ridempc.sim.scene import BOARD_PREFIX, Scene

if TYPE_CHECKING:
    from ridempc.scenarios.scenario import ParameterChange
    from ridempc.sim.changes import ScheduledChanges

__all__ = ["KNOBS", "PAYLOAD_OFFSET_MAX", "SCALE_MAX", "Action", "Knob"]

Array = NDArray[np.float64]
Action = Callable[[mujoco.MjData], None]


@dataclass(frozen=True)
class Knob:
    """One physical parameter a scenario can change.

    Attributes:
        unit: Unit of its value (``-`` for none).
        low: Lowest value it may take [unit].
        high: Highest value it may take [unit].
        low_open: Whether ``low`` itself is refused (a mass, a radius, a friction).
        forms: Which of ``value``, ``scale`` it takes (``payload``: neither).
        where: The field naming where it applies (``body``, ``gain``, ``joint``), or None.
        where_required: Whether that field must be given.
        what: What it changes, one line (the README's table).
        prepare: Checks a change against the scene, returns the action that applies it.
    """

    unit: str
    low: float
    high: float
    low_open: bool
    forms: frozenset[str]
    where: str | None
    where_required: bool
    what: str
    prepare: Callable[[ScheduledChanges, ParameterChange], Action]

    def allowed(self) -> str:
        unit = "" if self.unit == "-" else f" {self.unit}"
        return f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}]{unit}"

    def admits(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        return math.isfinite(value) and above and value <= self.high


SCALE_MAX: float = 10.0  # a scale above this is a typing error, not a robustness study
PAYLOAD_MASS_MAX: float = 100.0  # [kg] three Cassies
PAYLOAD_OFFSET_MAX: float = 1.0  # [m] per axis: farther is off the robot (Cassie is 1 m tall)


def _bodies_named(model: mujoco.MjModel, bodies: frozenset[int], prefix: str = "") -> dict:
    names = {}
    for b in sorted(bodies):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or ""
        names[name[len(prefix) :]] = b
    return names


def _friction(geoms_of: Callable[[Scene], frozenset[int]], what: str) -> Callable[..., Action]:
    def prepare(changes: ScheduledChanges, change: ParameterChange) -> Action:
        geoms = sorted(geoms_of(changes.scene))
        if not geoms:
            raise changes.refuse(change, f"this scene has no {what}")
        knob = KNOBS[change.parameter]
        values = [
            changes.target(change, changes.nominal["geom_friction"][g, 0], knob) for g in geoms
        ]

        def act(data: mujoco.MjData) -> None:
            changes.model.geom_friction[geoms, 0] = values

        return act

    return prepare


def _board_mass(changes: ScheduledChanges, change: ParameterChange) -> Action:
    scene = changes.scene
    names = _bodies_named(scene.model, scene.board_bodies, BOARD_PREFIX)
    if change.body not in names:
        raise changes.refuse(
            change,
            f"body '{change.body}' is not a body of the board "
            f"(valid: {', '.join(names) or 'none, no board'})",
        )
    body = names[change.body]
    mass0 = float(changes.nominal["body_mass"][body])
    mass = changes.target(change, mass0, KNOBS[change.parameter])
    inertia = changes.nominal["body_inertia"][body] * (mass / mass0)

    def act(data: mujoco.MjData) -> None:
        changes.model.body_mass[body] = mass
        changes.model.body_inertia[body] = inertia  # the same shape, heavier

    return act


def _payload_action(changes: ScheduledChanges, body: int, mass: float, offset: Array) -> Action:
    def act(data: mujoco.MjData) -> None:
        model = changes.model
        m0, c0 = float(model.body_mass[body]), model.body_ipos[body].copy()
        rot = np.empty(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[body])
        rot3 = rot.reshape(3, 3)
        inertia = rot3 @ np.diag(model.body_inertia[body]) @ rot3.T  # about c0, body frame
        total = m0 + mass
        com = (m0 * c0 + mass * offset) / total
        for m, at in ((m0, c0 - com), (mass, offset - com)):  # parallel axes
            inertia += m * (at @ at * np.eye(3) - np.outer(at, at))
        principal, axes = np.linalg.eigh(inertia)
        if np.linalg.det(axes) < 0.0:
            axes[:, 2] *= -1.0
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, axes.flatten())
        model.body_mass[body] = total
        model.body_ipos[body] = com
        model.body_inertia[body] = principal
        model.body_iquat[body] = quat

    return act


def _rider_body(changes: ScheduledChanges, change: ParameterChange, name: str) -> int:
    scene = changes.scene
    names = _bodies_named(scene.model, scene.rider_bodies)
    if name == "base":
        return scene.base_body
    if name not in names:
        raise changes.refuse(
            change, f"body '{name}' is not a rider body (valid: base, {', '.join(names)})"
        )
    return names[name]


def _payload(changes: ScheduledChanges, change: ParameterChange) -> Action:
    assert change.mass is not None and change.body is not None
    body = _rider_body(changes, change, change.body)
    if change.mass < 0.0:
        return _lighter(changes, change, body)
    return _payload_action(changes, body, change.mass, np.asarray(change.offset, dtype=float))


def _lighter(changes: ScheduledChanges, change: ParameterChange, root: int) -> Action:
    """A negative payload: the subtree of ``root`` scaled to ``change.mass`` less."""
    assert change.mass is not None
    parents = changes.model.body_parentid
    bodies = []
    for body in range(1, changes.model.nbody):
        up = body
        while up not in (0, root):
            up = int(parents[up])
        if up == root:
            bodies.append(body)
    masses = changes.nominal["body_mass"][bodies]
    subtree = float(np.sum(masses))
    if -change.mass >= subtree:
        raise changes.refuse(
            change,
            f"payload mass = {change.mass:g} kg takes off all of body '{change.body}' "
            f"and what it carries ({subtree:.4g} kg; a negative mass must be above {-subtree:.4g})",
        )
    scale = (subtree + change.mass) / subtree
    inertias = changes.nominal["body_inertia"][bodies] * scale

    def act(data: mujoco.MjData) -> None:
        changes.model.body_mass[bodies] = masses * scale
        changes.model.body_inertia[bodies] = inertias  # the same shapes, lighter

    return act


def _base_payload(changes: ScheduledChanges, change: ParameterChange) -> Action:
    assert change.value is not None
    body = changes.scene.base_body
    return _payload_action(changes, body, change.value, changes.nominal["body_ipos"][body])


def _motor_torque_limit(changes: ScheduledChanges, change: ParameterChange) -> Action:
    if changes.scene.robot is None:
        raise changes.refuse(change, "a dead weight has no motors")
    assert change.scale is not None
    scale = change.scale

    def act(data: mujoco.MjData) -> None:
        if changes.driver is None:  # checking only (no simulation)
            return
        changes.driver.scale_torque_limit(scale / changes.torque_scale)
        changes.torque_scale = scale

    return act


def _joint_damping(changes: ScheduledChanges, change: ParameterChange) -> Action:
    scene, model = changes.scene, changes.model
    joints = {
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "": j
        for j in range(model.njnt)
        if model.jnt_bodyid[j] in scene.rider_bodies
        and model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE
    }
    if not joints:
        raise changes.refuse(change, "the rider has no joints")
    if change.joint is not None and change.joint not in joints:
        raise changes.refuse(
            change, f"joint '{change.joint}' is not a robot joint (valid: {', '.join(joints)})"
        )
    chosen = [joints[change.joint]] if change.joint is not None else list(joints.values())
    dofs = [d for d in range(model.nv) if model.dof_jntid[d] in chosen]  # a ball has 3
    knob = KNOBS[change.parameter]
    values = [changes.target(change, changes.nominal["dof_damping"][d], knob) for d in dofs]

    def act(data: mujoco.MjData) -> None:
        changes.model.dof_damping[dofs] = values

    return act


def _board_field(
    path_of: Callable[[ScheduledChanges, ParameterChange], tuple[str, ...]],
) -> Callable[[ScheduledChanges, ParameterChange], Action]:
    """A knob that sets one field of the board's parameters, rebuilt by its builder."""

    def prepare(changes: ScheduledChanges, change: ParameterChange) -> Action:
        params = changes.board_params
        if params is None or changes.scene.board is None:
            raise changes.refuse(change, "there is no board")
        path = path_of(changes, change)
        nominal = _get(changes.nominal_board, path)
        if not isinstance(nominal, int | float):
            raise changes.refuse(
                change, f"board '{params.name}' (kind {params.kind}) has no {'.'.join(path)}"
            )
        value = changes.target(change, float(nominal), KNOBS[change.parameter])
        dump = params.model_dump()
        _set(dump, path, value)
        try:
            new = type(params).model_validate(dump)
        except ValidationError as exc:
            first = exc.errors()[0]
            raise changes.refuse(
                change,
                f"{'.'.join(path)} = {value:g} does not fit board '{params.name}': {first['msg']}",
            ) from exc
        changes.board_params = new
        return _board_rebuild(changes, params, new)

    return prepare


def _get(params: BoardParameters | None, path: tuple[str, ...]) -> Any:
    node: Any = params
    for key in path:
        node = getattr(node, key, None)
    return node


def _set(dump: dict[str, Any], path: tuple[str, ...], value: float) -> None:
    for key in path[:-1]:
        dump = dump[key]
    dump[path[-1]] = value


def _bushing(changes: ScheduledChanges, change: ParameterChange) -> tuple[str, ...]:
    return (change.parameter,)


def _wheel(changes: ScheduledChanges, change: ParameterChange) -> tuple[str, ...]:
    return ("wheel_radius",)


def _gain(changes: ScheduledChanges, change: ParameterChange) -> tuple[str, ...]:
    params = changes.board_params
    assert params is not None and change.gain is not None
    gains = type(params).firmware_gains()
    if change.gain not in gains:
        raise changes.refuse(
            change,
            f"'{change.gain}' is not a firmware gain of board '{params.name}' "
            f"(valid: {', '.join(gains) or f'none, the {params.kind} has no firmware gains'})",
        )
    return gains[change.gain]


def _board_rebuild(changes: ScheduledChanges, old: BoardParameters, new: BoardParameters) -> Action:
    """Copy what the board's builder changes between ``old`` and ``new`` into the scene."""
    assert changes.scene.board is not None
    edits = board_edits(changes.scene.board, old, new, changes.model, BOARD_PREFIX)
    firmware = changes.firmware

    def act(data: mujoco.MjData) -> None:
        edits.apply(changes.model, data)
        if firmware is not None:
            firmware.reconfigure(new)

    return act


def _knob(
    unit: str,
    low: float,
    high: float,
    what: str,
    prepare: Callable[[ScheduledChanges, ParameterChange], Action],
    low_open: bool = True,
    forms: tuple[str, ...] = ("value", "scale"),
    where: str | None = None,
    where_required: bool = True,
) -> Knob:
    return Knob(unit, low, high, low_open, frozenset(forms), where, where_required, what, prepare)


KNOBS: Mapping[str, Knob] = MappingProxyType(
    {
        # frictions: rubber on dry concrete is about 1; 3 is beyond any tyre, sole or deck
        "floor_friction": _knob(
            "-", 0.0, 3.0, "the floor's friction", _friction(lambda s: s.ground_geoms, "floor")
        ),
        "tyre_friction": _knob(
            "-",
            0.0,
            3.0,
            "the board's tyres' friction",
            _friction(lambda s: collision_geoms(s.model, s.board_ground_bodies), "board wheel"),
        ),
        "deck_friction": _knob(
            "-",
            0.0,
            3.0,
            "the board's platforms' friction",
            _friction(lambda s: s.deck_geoms, "board platform"),
        ),
        # a 100 kg board body is no longer a personal board
        "board_mass": _knob("kg", 0.0, 100.0, "one board body's mass", _board_mass, where="body"),
        # a 1 m wheel is a unicycle's; the boards' are 3-13 cm
        "wheel_radius": _knob("m", 0.0, 0.5, "the board's wheel radius", _board_field(_wheel)),
        # bushings: the skateboard's are 12 N m/rad and 0.3 N m s/rad; 1000 is a rigid truck
        "bushing_stiffness": _knob(
            "N m/rad", 0.0, 1000.0, "each truck's bushing stiffness", _board_field(_bushing)
        ),
        "bushing_damping": _knob(
            "N m s/rad",
            0.0,
            100.0,
            "each truck's bushing damping",
            _board_field(_bushing),
            low_open=False,
        ),
        # the firmwares' largest gain is the Segway's pitch_kp, 250 N m/rad
        "firmware_gain": _knob(
            "gain's",
            0.0,
            1.0e4,
            "one gain of the board's firmware",
            _board_field(_gain),
            low_open=False,
            where="gain",
        ),
        "payload": _knob(
            "kg",
            -PAYLOAD_MASS_MAX,  # negative: a lighter rider, at most all of the body's subtree
            PAYLOAD_MASS_MAX,
            "a point mass on a rider body",
            _payload,
            forms=(),
            where="body",
        ),
        "base_payload": _knob(
            "kg",
            0.0,
            PAYLOAD_MASS_MAX,
            "a mass at the base's centre of mass",
            _base_payload,
            forms=("value",),
        ),
        # five times its peak torque is no longer the same motor
        "motor_torque_limit": _knob(
            "-",
            0.0,
            5.0,
            "every robot motor's peak torque",
            _motor_torque_limit,
            forms=("scale",),
        ),
        # the robots' joints have 0.01-1 N m s/rad
        "joint_damping": _knob(
            "N m s/rad",
            0.0,
            100.0,
            "the robot joints' damping",
            _joint_damping,
            low_open=False,
            where="joint",
            where_required=False,
        ),
    }
)
