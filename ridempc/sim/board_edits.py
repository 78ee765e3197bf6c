"""A board parameter changed in a compiled scene: what the board's own builder changes with it.

The board is built from its parameters by its kind's builder (:mod:`ridempc.boards.kinds`),
so a new wheel radius changes the tyre's size, the wheel's inertia, the axle's place under
the deck and whatever else the builder derives from it. :func:`board_edits` builds the board
alone before and after, and lists every figure that differs, by element name, for the
scene's copy of the board (prefix ``board/``). A free platform whose frame moves against its
own geometry (the Hovershoes' and the Segway's frames sit on the axle, which moves with the
wheel radius while the deck stays at its height) is moved by that offset, so nothing jumps.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from ridempc.boards.board import Board
from ridempc.boards.parameters import BoardParameters
from ridempc.errors import ConfigError

__all__ = ["BoardEdits", "board_edits"]

Array = NDArray[np.float64]

# Per element kind, the arrays a board's builder may change with one of its parameters.
_FIELDS: tuple[tuple[mujoco.mjtObj, tuple[str, ...]], ...] = (
    (
        mujoco.mjtObj.mjOBJ_BODY,
        ("body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia"),
    ),
    (
        mujoco.mjtObj.mjOBJ_GEOM,
        ("geom_size", "geom_pos", "geom_quat", "geom_friction", "geom_rbound", "geom_aabb"),
    ),
    (mujoco.mjtObj.mjOBJ_SITE, ("site_pos", "site_quat")),
    (mujoco.mjtObj.mjOBJ_JOINT, ("jnt_stiffness", "jnt_range", "jnt_pos", "jnt_axis")),
    (mujoco.mjtObj.mjOBJ_ACTUATOR, ("actuator_ctrlrange", "actuator_gear")),
)
_DOF_FIELDS: tuple[str, ...] = ("dof_damping", "dof_frictionloss", "dof_armature")
WRITTEN: tuple[str, ...] = (*(f for _, fields in _FIELDS for f in fields), *_DOF_FIELDS)


@dataclass
class BoardEdits:
    """What changes in the scene.

    Attributes:
        values: (model array, scene index, new value) for each changed figure.
        shifts: (qpos address, dof address, offset in the body frame [m]) of each free
            platform whose frame moves against its geometry.
    """

    values: list[tuple[str, int, Array]] = field(default_factory=list)
    shifts: list[tuple[int, int, Array]] = field(default_factory=list)

    def apply(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        for name, i, value in self.values:
            getattr(model, name)[i] = value
        rot = np.empty(9)
        for qpos, dof, offset in self.shifts:
            mujoco.mju_quat2Mat(rot, data.qpos[qpos + 3 : qpos + 7])
            moved = rot.reshape(3, 3) @ offset
            data.qpos[qpos : qpos + 3] += moved
            spin = rot.reshape(3, 3) @ data.qvel[dof + 3 : dof + 6]  # free joint: body frame
            data.qvel[dof : dof + 3] += np.cross(spin, moved)


def _is_free_root(model: mujoco.MjModel, body: int) -> bool:
    joint = model.body_jntadr[body]
    return bool(joint >= 0 and model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE)


def board_edits(
    board: Board,
    old: BoardParameters,
    new: BoardParameters,
    scene: mujoco.MjModel,
    prefix: str,
) -> BoardEdits:
    """The figures of the scene's board that change from ``old`` to ``new`` parameters.

    Args:
        board: The scene's board (its kind's builder).
        old: The parameters the scene's board has now.
        new: The changed parameters.
        scene: The compiled scene.
        prefix: Name prefix of the board's elements in the scene.
    """
    before = board.kind.build(old).compile()
    after = board.kind.build(new).compile()
    edits = BoardEdits()

    def scene_id(kind: mujoco.mjtObj, i: int) -> int:
        name = mujoco.mj_id2name(before, kind, i)
        found = mujoco.mj_name2id(scene, kind, prefix + (name or ""))
        if not name or found < 0:
            raise ConfigError(f"board '{new.name}': its {kind.name} {i} is not in the scene")
        return found

    for kind, fields in _FIELDS:
        for name in fields:
            old_values, new_values = getattr(before, name), getattr(after, name)
            if old_values.size == 0:
                continue
            changed = (old_values != new_values).reshape(len(old_values), -1).any(axis=1)
            for i in map(int, np.flatnonzero(changed)):
                if name == "body_pos" and _is_free_root(before, i):
                    joint = int(scene.body_jntadr[scene_id(kind, i)])
                    edits.shifts.append(
                        (
                            int(scene.jnt_qposadr[joint]),
                            int(scene.jnt_dofadr[joint]),
                            new_values[i] - old_values[i],
                        )
                    )
                else:
                    edits.values.append((name, scene_id(kind, i), new_values[i].copy()))
    for j in range(before.njnt):
        if before.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            continue
        dof, scene_dof = before.jnt_dofadr[j], None
        for name in _DOF_FIELDS:
            if getattr(before, name)[dof] != getattr(after, name)[dof]:
                if scene_dof is None:
                    scene_dof = int(scene.jnt_dofadr[scene_id(mujoco.mjtObj.mjOBJ_JOINT, j)])
                edits.values.append((name, scene_dof, np.asarray(getattr(after, name)[dof])))
    return edits
