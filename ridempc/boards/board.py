"""A board: its parameter file, its kind, and what follows from them."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import mujoco
import numpy as np

from ridempc.boards.firmware import BoardIO, Firmware
from ridempc.boards.kinds import BoardKind, board_kind
from ridempc.boards.parameters import (
    BoardParameters,
    read_board_toml,
    validate_board_parameters,
)
from ridempc.errors import ConfigError

__all__ = ["Board", "load_board_file"]


@dataclass(frozen=True)
class Board:
    """A board read from ``boards/<name>/board.toml``."""

    params: BoardParameters
    folder: Path

    @property
    def name(self) -> str:
        return self.params.name

    @property
    def kind(self) -> BoardKind:
        return board_kind(self.params.kind)

    def spec(self) -> mujoco.MjSpec:
        """The board's own MuJoCo spec, built from its parameters."""
        return self.kind.build(self.params)

    def firmware(self, io: BoardIO) -> Firmware:
        return self.kind.firmware(self.params, io)

    @cached_property
    def mj_model(self) -> mujoco.MjModel:
        """The board compiled alone, for reading its figures."""
        return self.spec().compile()

    @cached_property
    def mass(self) -> float:
        """Total mass [kg]."""
        return float(self.mj_model.body_mass.sum())

    @cached_property
    def platform_top(self) -> float:
        """Mean height of the platform sites (the decks' top surfaces) at rest [m]."""
        data = mujoco.MjData(self.mj_model)
        mujoco.mj_forward(self.mj_model, data)
        return float(np.mean([data.site(s).xpos[2] for s in self.params.platform_sites]))

    def mjcf(self) -> str:
        """The board's description as MJCF text (what Pinocchio reads)."""
        spec = self.spec()
        spec.compile()
        return str(spec.to_xml())


def load_board_file(path: Path) -> Board:
    """Read and check a board parameter file.

    Raises:
        ConfigError: Missing or non-physical value, unknown kind; the field is named.
    """
    raw = read_board_toml(path)
    kind_name = raw.get("kind")
    if not isinstance(kind_name, str):
        raise ConfigError(f"{path}: field 'kind': missing (one of hovershoes, segway, skateboard)")
    try:
        kind = board_kind(kind_name)
    except KeyError as exc:
        raise ConfigError(f"{path}: field 'kind': {exc}") from exc
    params = validate_board_parameters(path, raw, kind.parameters)
    if params.name != path.parent.name:
        raise ConfigError(
            f"{path}: field 'name': is '{params.name}', expected '{path.parent.name}'"
        )
    board = Board(params=params, folder=path.parent)
    _check_names(path, board)
    return board


def _check_names(path: Path, board: Board) -> None:
    """The sites and bodies the file names exist in the model its figures build."""
    try:
        model = board.mj_model
    except ValueError as exc:
        raise ConfigError(f"{path}: MuJoCo cannot build the board from it ({exc})") from exc
    for field, names, kind, count in (
        ("platform_sites", board.params.platform_sites, mujoco.mjtObj.mjOBJ_SITE, model.nsite),
        ("ground_bodies", board.params.ground_bodies, mujoco.mjtObj.mjOBJ_BODY, model.nbody),
    ):
        valid = [mujoco.mj_id2name(model, kind, i) for i in range(count)]
        for name in names:
            if name not in valid:
                raise ConfigError(
                    f"{path}: field '{field}': '{name}' is not in the board's model "
                    f"(valid: {', '.join(v for v in valid if v)})"
                )
