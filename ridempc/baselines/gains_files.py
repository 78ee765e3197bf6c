"""Which gains file a PD baseline reads: the one its robot-board pair file names.

A baseline's numbers that depend on the robot (its mass, its stance, its joint PD) live in a
gains file beside the baselines; a pair file (``pairs/<robot>-<board>.toml``) names its own
in ``pd_gains``, and a pair that names none, or a robot on a board without a pair file (a
quadruped on flat ground), gets the baseline's default file.
"""

from __future__ import annotations

from pathlib import Path

from ridempc.pair_description import load_pair_description, pair_description_names

__all__ = ["GAINS_FOLDER", "gains_file_names", "pair_gains_file"]

GAINS_FOLDER: Path = Path(__file__).parent  # the baselines' gains files sit beside them


def gains_file_names() -> tuple[str, ...]:
    """The gains files a pair file may name (``pd_gains``), sorted."""
    return tuple(sorted(p.name for p in GAINS_FOLDER.glob("*.toml")))


def pair_gains_file(robot: str, board: str, default: Path) -> Path:
    """The gains file the pair file of ``robot`` on ``board`` names, else ``default``.

    Raises:
        ConfigError: The pair file is malformed (:func:`~ridempc.pair_description.
            load_pair_description`).
    """
    if f"{robot}-{board}" not in pair_description_names():
        return default
    named = load_pair_description(robot, board).pd_gains
    return default if named is None else GAINS_FOLDER / named
