"""The controllers are generic: no robot, board, body, joint or site name of any description
is written into ``ridempc/mpc``, ``ridempc/wbc`` or ``ridempc/trajopt``, and no ``isinstance``
asks what kind of board or robot it has; names come from the descriptions (``robot.toml``,
``board.toml``, ``pairs/*.toml``) and kinds from the board's features."""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from ridempc.boards import board_names, load_board
from ridempc.robots import load_robot, robot_names

PACKAGE = Path(__file__).resolve().parents[1] / "ridempc"
CONTROLLERS = ("mpc", "wbc", "trajopt")
FILES = sorted(f for folder in CONTROLLERS for f in (PACKAGE / folder).glob("*.py"))


def _description_names() -> set[str]:
    """Every name a robot or board description declares."""
    names: set[str] = set()
    for name in robot_names():
        p = load_robot(name).params
        names |= {name, p.base_body, p.imu_site, *p.foot_bodies, *p.contact_sites}
        names |= {*p.motors, *p.encoder_joints}
    for name in board_names():
        board = load_board(name)
        if board is not None:
            names |= {name, *board.params.platform_sites, *board.params.ground_bodies}
    return names


NAMES = _description_names()


def _docstrings(tree: ast.AST) -> set[int]:
    kinds = (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)
    return {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, kinds)
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }


def _code_strings(path: Path) -> Iterator[tuple[int, str]]:
    """The string constants of the code (not docstrings, not prose: no spaces)."""
    tree = ast.parse(path.read_text())
    docs = _docstrings(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            if id(node) not in docs and " " not in node.value:
                yield node.lineno, node.value


def test_the_names_checked_are_the_descriptions() -> None:
    assert {"cassie", "cyberdog2", "pelvis", "trunk", "RL_contact", "segway"} <= NAMES
    assert len(FILES) > 30


@pytest.mark.parametrize("path", FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_no_description_name_in_the_controllers(path: Path) -> None:
    found = []
    for line, text in _code_strings(path):
        tokens = {t.strip("_") for t in re.split(r"[^A-Za-z0-9_]+", text)}
        found += [f"{path.name}:{line}: {text!r} ({name})" for name in sorted(NAMES & tokens)]
    assert not found, found


@pytest.mark.parametrize("path", FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_no_isinstance_on_board_or_robot_types(path: Path) -> None:
    kinds = re.compile(r"(Parameters|Board|Robot|RobotModel|SkateboardModel)$")
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id == "isinstance"
            and len(node.args) == 2
        ):
            names = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
            found += [f"{path.name}:{node.lineno}: {n}" for n in names if kinds.search(n)]
    assert not found, found
