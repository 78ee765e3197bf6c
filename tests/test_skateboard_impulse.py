"""The skateboard pairs' ``[stages.impulse]`` bands from their physics, and a short ride
each side of the band (CyberDog2, 1.3 s).

Along the deck the wheels roll under the rider, who tips over its own front or rear feet
once its capture point passes them: the reach is :math:`x_f \\sqrt{g / h}` [m/s], with
:math:`x_f` the feet's half-length and :math:`h` the centre of mass over the soles. Across,
the deck rolls on its bushings with the rider, and the whole tips over the wheels' line:
:math:`(w/2) \\sqrt{g / H}`, with :math:`w` the trucks' width and :math:`H` the centre of
mass over the ground.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

import ridempc
from ridempc.boards.registry import load_board
from ridempc.pair_description import load_pair_description
from ridempc.robots.robot import load_robot
from ridempc.scenarios.library import resolve_scenario
from ridempc.scenarios.scenario import Disturbance, Scenario

GRAVITY = 9.81  # [m/s^2]
LIBRARY_PUSH = 0.2  # [m/s] the library's push on the skateboard: 1 N/kg for 0.2 s, sideways
OVER_READ = 1.15  # [-] the observer reads the library's push as 0.23 m/s (mass and forces modelled)
ROUNDING = 0.02  # [m/s] the pair files give the bands to two figures


def _reaches(robot_name: str) -> tuple[float, float]:
    """The capture point's reach along the deck and across it [m/s], from the robot's
    riding stance and the board's geometry."""
    robot = load_robot(robot_name)
    model = robot.mj_model
    data = mujoco.MjData(model)
    data.qpos[:] = robot.stance_qpos("skateboard")
    mujoco.mj_forward(model, data)
    sites = [
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
        for name in robot.params.contact_sites
    ]
    feet = data.site_xpos[sites]
    com = data.subtree_com[0]
    soles = feet[:, 2].mean() - _foot_radius(model, robot.params.foot_bodies)
    h = float(com[2] - soles)  # [m] over the soles
    half_length = float(np.abs(feet[:, 0] - feet[:, 0].mean()).mean())
    board = load_board("skateboard")
    assert board is not None
    params = board.params
    big_h = h + float(params.height)  # [m] over the ground: the soles stand on the deck's top
    along = half_length * math.sqrt(GRAVITY / h)
    across = params.truck_width / 2.0 * math.sqrt(GRAVITY / big_h)
    return along, across


def _foot_radius(model: mujoco.MjModel, bodies: tuple[str, ...] | list[str]) -> float:
    ids = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in bodies}
    return max(
        float(model.geom_size[g, 0])
        for g in range(model.ngeom)
        if model.geom_bodyid[g] in ids and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE
    )


@pytest.mark.parametrize("robot", ["cyberdog2", "go1"])
def test_the_bands_are_the_capture_points_reach(robot: str) -> None:
    stage = load_pair_description(robot, "skateboard").stages.impulse
    assert stage is not None and stage.sideways is not None
    along, across = _reaches(robot)
    assert stage.band == pytest.approx(along, abs=ROUNDING)
    assert stage.sideways == pytest.approx(across, abs=ROUNDING)
    assert stage.sideways > LIBRARY_PUSH * OVER_READ  # the library's push rides on the MPC


def _pushed(magnitude: float) -> Scenario:
    """Standing still, pushed sideways at 0.5 s for 0.2 s by ``magnitude`` [N/kg]."""
    base = resolve_scenario("stand-still", "skateboard")
    push = Disturbance(t=0.5, force=(0.0, magnitude, 0.0), duration=0.2, per_kg=True)
    return base.model_copy(update={"disturbances": (push,), "name": "pushed"})


def test_a_library_push_stays_on_the_mpc_and_a_shove_goes_to_the_pd() -> None:
    library = ridempc.ride("cyberdog2", "skateboard", "mpc", _pushed(1.0), duration=1.3)
    assert not library["fell"] and not library["fallbacks"]
    assert LIBRARY_PUSH <= library["impulse_max"] < 0.62
    shove = ridempc.ride("cyberdog2", "skateboard", "mpc", _pushed(4.0), duration=1.3)
    reasons = [f["reason"] for f in shove["fallbacks"]]
    assert reasons and reasons[0].startswith("pushed by")
    assert shove["fallbacks"][0]["time_s"] < 0.7  # within the push
