"""A scenario's parameter changes (``[[changes]]``), applied to the compiled scene on time.

Each change turns one knob of :data:`ridempc.sim.knobs.KNOBS` to ``value``, or to ``scale``
times its nominal value (the scene as built from the robot's and board's descriptions), at
the physics step of its time ``t``: the changes at ``t = 0`` before the first step, so a
heavier rider starts heavier. The scenario model checks each change's range when it is
loaded (:class:`~ridempc.scenarios.scenario.ParameterChange`); :class:`ScheduledChanges`
checks the names against the scene, and the scaled values, when the simulation is made,
before the ride, and undoes every change after it. After a change MuJoCo's derived constants
are recomputed (``mj_setConst``) and the state forwarded.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco

from ridempc.boards.firmware import Firmware
from ridempc.boards.parameters import BoardParameters
from ridempc.errors import ConfigError
from ridempc.sim.board_edits import WRITTEN
from ridempc.sim.contact_pairs import set_pair_friction
from ridempc.sim.knobs import KNOBS, Action, Knob
from ridempc.sim.motors import MotorDriver

if TYPE_CHECKING:
    from ridempc.scenarios.scenario import ParameterChange
    from ridempc.sim.scene import Scene

__all__ = ["ScheduledChanges"]

# The model arrays a change may write; each run starts from and returns to them.
_WRITTEN: tuple[str, ...] = (*WRITTEN, "pair_friction")


class ScheduledChanges:
    """A scenario's changes, checked against a scene and due at their physics steps.

    Args:
        scene: The compiled scene.
        changes: The scenario's changes.
        firmware: The board's firmware (None without a board, or to check only).
        driver: The robot's motor drivers (None for a dead weight, or to check only):
            ``ScheduledChanges(scene, changes, None, None, where)`` right after the scene
            is built checks the changes before anything else is made.
        where: What to name in errors (the scenario).

    Raises:
        ConfigError: A change that does not apply to this robot and board (a bushing on
            the Hovershoes, an unknown body, a scaled value out of its range).
    """

    def __init__(
        self,
        scene: Scene,
        changes: tuple[ParameterChange, ...],
        firmware: Firmware | None,
        driver: MotorDriver | None,
        where: str,
    ) -> None:
        self.scene = scene
        self.model = scene.model
        self.firmware = firmware
        self.driver = driver
        self.where = where
        self.nominal = {name: getattr(self.model, name).copy() for name in _WRITTEN}
        self.board_params: BoardParameters | None = (
            scene.board.params if scene.board is not None else None
        )
        self.nominal_board = self.board_params
        self._nominal_firmware = firmware.params if firmware is not None else None
        self.torque_scale = 1.0  # what the driver's limits are now, times the description's
        self._scratch: mujoco.MjData | None = None
        self._due: dict[int, list[Action]] = {}
        self._index = 0
        hz = scene.physics_hz
        for index, change in sorted(enumerate(changes), key=lambda ic: ic[1].t):
            self._index = index
            action = KNOBS[change.parameter].prepare(self, change)
            self._due.setdefault(round(change.t * hz), []).append(action)

    def __bool__(self) -> bool:
        return bool(self._due)

    def refuse(self, change: ParameterChange, why: str) -> ConfigError:
        return ConfigError(f"{self.where}: changes[{self._index}] ({change.parameter}): {why}")

    def target(self, change: ParameterChange, nominal: float, knob: Knob) -> float:
        """The value a change sets, from its ``value`` or ``scale`` times ``nominal``."""
        if change.value is not None:
            return change.value
        assert change.scale is not None
        value = change.scale * nominal
        if not knob.admits(value):
            raise self.refuse(
                change,
                f"scale {change.scale:g} of the nominal {nominal:g} gives {value:g}, "
                f"outside {knob.allowed()}",
            )
        return value

    def apply(self, tick: int, data: mujoco.MjData) -> bool:
        """Apply the changes due at physics step ``tick``; returns whether there were any."""
        actions = self._due.get(tick)
        if not actions:
            return False
        for action in actions:
            action(data)
        self._settle(data)
        return True

    def restore(self) -> None:
        """Undo every change (the scene's model, the firmware, the motor limits)."""
        for name, values in self.nominal.items():
            getattr(self.model, name)[:] = values
        if self._scratch is not None:
            mujoco.mj_setConst(self.model, self._scratch)
        self.board_params = self.nominal_board
        if self.firmware is not None and self._nominal_firmware is not None:
            self.firmware.reconfigure(self._nominal_firmware)
        if self.driver is not None and self.torque_scale != 1.0:
            self.driver.scale_torque_limit(1.0 / self.torque_scale)
        self.torque_scale = 1.0

    def _settle(self, data: mujoco.MjData) -> None:
        model = self.model
        set_pair_friction(model, self.nominal["pair_friction"], self.nominal["geom_friction"])
        if self._scratch is None:
            self._scratch = mujoco.MjData(model)
        mujoco.mj_setConst(model, self._scratch)  # masses, inertias: what MuJoCo derives
        mujoco.mj_forward(model, data)
