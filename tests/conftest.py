"""Shared fixtures: robots by name, one generated test per robot."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")

from ridempc.robots import load_robot, robot_names  # noqa: E402

ROBOTS = robot_names()


@pytest.fixture(params=ROBOTS)
def robot(request: pytest.FixtureRequest):
    return load_robot(request.param)
