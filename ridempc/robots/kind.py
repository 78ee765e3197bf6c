"""A robot's kind by its name, for data that apply to every robot of a kind (a scenario's
``robot_kinds``): ``robot.toml``'s ``kind``."""

from __future__ import annotations

from typing import Literal

from ridempc.paths import robots_dir
from ridempc.robots.parameters import load_robot_parameters

__all__ = ["RobotKind", "robot_kind"]

RobotKind = Literal["biped", "quadruped"]  # the kinds robot.toml allows


def robot_kind(name: str) -> str | None:
    """The kind of the robot named ``name``, or None where no robot has that name (the
    dead weight ``none``, or a name no folder of ``robots/`` holds).

    Raises:
        ConfigError: The robot's ``robot.toml`` is malformed.
    """
    path = robots_dir() / name / "robot.toml"
    if "/" in name or name in ("", ".", "..") or not path.is_file():
        return None
    return load_robot_parameters(path).kind
