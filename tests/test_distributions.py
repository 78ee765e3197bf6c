"""Distributions (ridempc.sweep.distribution): the shipped files load for their boards, the
laws draw within their ranges, and every bad file is refused in one line naming the file,
the field, the value and what is allowed."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from ridempc.boards import board_names
from ridempc.cli import main
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.sweep.distribution import (
    DISTRIBUTIONS_DIR,
    Law,
    distribution_files,
    distribution_names,
    load_distribution,
)

BOARDS = [b for b in board_names() if b != "none"]

GOOD = """
name = "mine"
[[pushes]]
magnitude = {uniform = [0.0, 2.0]}
t = 3.0
"""


def _file(tmp_path: Path, text: str) -> str:
    path = tmp_path / "mine.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("board", BOARDS)
def test_every_board_has_everyday_and_hard(board: str) -> None:
    assert {"everyday", "hard"} <= set(distribution_names(board))
    for name in ("everyday", "hard"):
        distribution = load_distribution(name, board)
        assert distribution.name == name and distribution.board == board
        assert distribution.description
        laws = distribution.quantities(platforms=2)
        assert "push.magnitude" in laws and "noise.scale" in laws
        assert any(n.startswith("kick") for n in laws) and "payload.fraction" in laws


def test_the_shipped_files_are_in_board_folders() -> None:
    assert distribution_files()
    for path in distribution_files():
        assert path.parent.name in BOARDS and path.parent.parent == DISTRIBUTIONS_DIR
    assert set(distribution_names()) == {"everyday", "hard", "everyday-terrain", "hard-terrain"}


def test_hard_is_wider_than_everyday() -> None:
    for board in BOARDS:
        everyday = load_distribution("everyday", board).quantities(2)
        hard = load_distribution("hard", board).quantities(2)
        push = "push.magnitude"
        assert hard[push].bounds()[1] > everyday[push].bounds()[1]
        assert hard["payload.fraction"].bounds() == (-0.3, 0.3)
        assert hard["noise.scale"].bounds()[1] == 2.0
        assert hard["changes.motor_torque_limit.scale"].bounds()[0] == 0.8


def test_a_path_and_a_distribution_for_any_board(tmp_path: Path) -> None:
    for board in BOARDS:
        assert load_distribution(_file(tmp_path, GOOD), board).board is None


def test_laws_draw_within_their_ranges() -> None:
    rng = np.random.default_rng(0)
    uniform = Law(uniform=(1.0, 2.0))
    normal = Law(normal=(0.0, 1.0), clip=(-0.5, 0.5))
    choice = Law(choice=(0.0, 90.0, 180.0))
    for law in (uniform, normal, choice):
        draws = [law.draw(rng) for _ in range(200)]
        low, high = law.bounds()
        assert all(low <= d <= high for d in draws) and law.random
    assert {choice.draw(rng) for _ in range(100)} == {0.0, 90.0, 180.0}
    state = rng.bit_generator.state
    assert Law(fixed=3.0).draw(rng) == 3.0 and not Law(fixed=3.0).random
    assert rng.bit_generator.state == state  # a fixed value takes no draw


@pytest.mark.parametrize(
    "edit, words",
    [
        ("magnitude = {uniform = [2.0, 1.0]}", "field 'pushes.0.magnitude': uniform = [2, 1]"),
        ("magnitude = {uniform = [1.0, 1.0]}", "is empty or inverted; allowed: [low, high]"),
        ("magnitude = {uniform = [0.0, 200.0]}", "draws in [0, 200]; allowed: within [0, 100]"),
        ("magnitude = {uniform = [0.0, nan]}", "pushes.0.magnitude.uniform.1"),
        ("magnitude = {uniform = [0.0, inf]}", "pushes.0.magnitude.uniform.1"),
        ("magnitude = '1.0'", "field 'pushes.0.magnitude.fixed': Input should be a valid number"),
        ("magnitude = {normal = [1.0, 0.5]}", "clip = [low, high] goes with normal"),
        ("magnitude = {normal = [1.0, 0.0], clip = [0.0, 2.0]}", "normal std = 0"),
        ("magnitude = {uniform = [0.0, 1.0], choice = [1.0]}", "got uniform and choice"),
        ("magnitude = {choice = []}", "pushes.0.magnitude.choice"),
        ("magnitude = {uniform = [0.0, 1.0]}\nforce = 3.0", "'pushes.0.force': unknown key"),
        ("magnitude = 1.0\nduration = 0.0", "draws in [0, 0]; allowed: within (0, 5] s"),
    ],
)
def test_a_bad_push_is_refused_in_one_line(tmp_path: Path, edit: str, words: str) -> None:
    text = GOOD.replace("magnitude = {uniform = [0.0, 2.0]}", edit)
    path = _file(tmp_path, text)
    with pytest.raises(ConfigError) as caught:
        load_distribution(path, "segway")
    message = str(caught.value)
    assert message.startswith(f"{path}:") and words in message and "\n" not in message


@pytest.mark.parametrize(
    "table, words",
    [
        (
            '[[changes]]\nparameter = "board_mass"\nbody = "deck"\nscale = {uniform = [0.5, 20.0]}',
            "field 'changes.0': board_mass scale = 20.0 is outside (0, 10]",
        ),
        (
            '[[changes]]\nparameter = "floor_friction"\nvalue = {uniform = [0.0, 1.0]}',
            "floor_friction value = 0.0 is outside (0, 3]",
        ),
        (
            '[[changes]]\nparameter = "motor_torque_limit"\nvalue = 0.8',
            "motor_torque_limit takes no value",
        ),
        ('[[changes]]\nparameter = "floor_friction"', "takes exactly one of value or scale"),
        ('[[changes]]\nparameter = "gravity"\nvalue = 1.0', "unknown knob 'gravity'"),
        ('[[changes]]\nparameter = "payload"', "a payload is drawn in the [payload] table"),
        (
            '[[changes]]\nparameter = "tyre_friction"\nscale = 0.9\n'
            '[[changes]]\nparameter = "tyre_friction"\nscale = {uniform = [0.5, 0.9]}',
            "changes.tyre_friction is drawn twice",
        ),
        ("[payload]\nfraction = {uniform = [0.0, 1.5]}", "allowed: within [-0.5, 1]"),
        ("[payload]\nfraction = 0.1\noffset = [0.0, 0.0, 2.0]", "within [-1, 1] m"),
        ("[noise]\nscale = {uniform = [0.0, 2.0]}", "allowed: within (0, 10]"),
        ("[start]\nfoot_offset = [0.6, 0.0]", "allowed: within [-0.5, 0.5] m"),
        ("[start]\nplatform_offsets = [0.01, 0.0]", "board 'segway' has no independent"),
        ('board = "hovershoes"', "field 'board': is 'hovershoes'; allowed: 'segway'"),
    ],
)
def test_bad_tables_are_refused_in_one_line(tmp_path: Path, table: str, words: str) -> None:
    head, tail = GOOD.split("[[pushes]]")
    if table.startswith("board"):
        text = head + table + "\n[[pushes]]" + tail
    else:
        text = GOOD + table + "\n"
    path = _file(tmp_path, text)
    with pytest.raises(ConfigError) as caught:
        load_distribution(path, "segway")
    message = str(caught.value)
    assert message.startswith(f"{path}:") and words in message and "\n" not in message


def test_unknown_names_list_the_valid_ones(tmp_path: Path) -> None:
    with pytest.raises(UnknownNameError, match=r"unknown distribution 'stormy' \(valid: everyday"):
        load_distribution("stormy", "segway")
    with pytest.raises(UnknownNameError, match="unknown board 'surfboard'"):
        load_distribution("everyday", "surfboard")
    with pytest.raises(ConfigError, match="missing.toml"):
        load_distribution(str(tmp_path / "missing.toml"), "segway")


def test_several_pushes_are_numbered(tmp_path: Path) -> None:
    text = GOOD + "[[pushes]]\nmagnitude = 1.0\nt = 5.0\n"
    laws = load_distribution(_file(tmp_path, text), "segway").quantities()
    assert {"push.0.magnitude", "push.1.t"} <= set(laws)
    assert math.isclose(laws["push.1.duration"].bounds()[0], 0.2)


def test_ridempc_list_names_the_distributions_and_their_boards(capsys) -> None:
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    listed = out.split("distributions")[1]
    for name in ("everyday", "hard"):
        assert f"{name:<16} boards: hovershoes, segway, skateboard" in listed
