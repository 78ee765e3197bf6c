"""The friction pyramid (``ridempc.friction``) against the simulator's own contact.

- The MPC's rows on a contact are the inner pyramid: its corners in, 1 % beyond them out;
  likewise the diamond's (the Hovershoes' shape), every force of which is inside the cone.
- In MuJoCo, the CyberDog2 foot's sphere (its radius, friction and contact parameters from
  the description) held on the scene's floor and pushed sideways at a corner of the pyramid:
  at the inner pyramid's corner of the controllers' :math:`\\mu` it stays put; at the outer
  pyramid's it slides away (MuJoCo's pyramidal cone is a diamond, module docstring).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
import pytest

from ridempc.friction import pyramid_matrix, pyramid_rows, pyramid_slope
from ridempc.robots import load_robot
from ridempc.sim.clock import DEFAULT_PHYSICS_HZ
from ridempc.sim.scene import build_scene
from ridempc.wbc.settings import WbcSettings

MU = WbcSettings().friction  # the controllers' Coulomb coefficient, 0.6


def _foot_slide(
    slope: float, seconds: float = 0.5, axes: tuple[float, float] = (1.0, 1.0)
) -> float:
    """How far [m] the dog's foot sphere slides on the scene's floor in ``seconds`` when
    pushed with a tangential force of ``slope`` times its weight along each of ``axes`` (x
    and y, both by default; only its translations are free, as a foot held by its leg)."""
    robot = load_robot("cyberdog2")
    scene = build_scene(robot, DEFAULT_PHYSICS_HZ)
    model = scene.model
    foot = model.geom(model.body(robot.params.foot_bodies[0]).geomadr[0])
    floor = model.geom("floor")

    def contact(geom: Any) -> str:
        return " ".join(
            f'{key}="{" ".join(map(str, getattr(geom, key)))}"'
            for key in ("friction", "solref", "solimp")
        )

    xml = f"""
    <mujoco>
      <option timestep="{model.opt.timestep}" cone="pyramidal"/>
      <worldbody>
        <geom name="floor" type="plane" size="2 2 0.1" {contact(floor)}/>
        <body name="foot" pos="0 0 {foot.size[0]}">
          <joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 0"/>
          <joint type="slide" axis="0 0 1"/>
          <geom type="sphere" size="{foot.size[0]}" mass="2.0" {contact(foot)}/>
        </body>
      </worldbody>
    </mujoco>"""
    assert model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL  # the rides' contact model
    assert float(foot.friction[0]) == pytest.approx(1.0) and float(floor.friction[0]) >= 1.0
    small = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(small)
    body = small.body("foot").id
    weight = 2.0 * -small.opt.gravity[2]
    for _ in range(int(0.2 / small.opt.timestep)):  # settle
        mujoco.mj_step(small, data)
    start = data.qpos[:2].copy()
    data.xfrc_applied[body, :2] = slope * weight * np.asarray(axes)
    for _ in range(int(seconds / small.opt.timestep)):
        mujoco.mj_step(small, data)
    return float(np.linalg.norm(data.qpos[:2] - start))


def test_mujoco_holds_the_inner_pyramid_and_lets_the_outer_one_slip() -> None:
    inner = _foot_slide(pyramid_slope(MU))
    outer = _foot_slide(MU)
    # the soft contact creeps ~0.8 mm under any load below the diamond; at 0.51 it slides 18 mm
    assert inner < 2e-3, f"inner pyramid corner slid {inner:.4f} m"
    assert outer > 0.05, f"outer pyramid corner slid only {outer:.4f} m"


def test_mpc_pyramid_rows_are_the_inner_pyramid() -> None:
    """The MPC's rows on one ground contact accept a force at the inner pyramid's corner and
    refuse one just outside it (its corner 1 % further out)."""
    from ridempc.mpc.friction import friction_pyramids
    from ridempc.trajopt.schedule import Contact

    index = np.array([[0, 1, 2]])
    matrix, lower, upper = friction_pyramids(
        index, 3, [[Contact.GROUND]], np.eye(3)[None], MU, max_force=100.0
    )
    s = pyramid_slope(MU)
    for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        inside = np.array([sx * s, sy * s, 1.0]) * 20.0
        outside = np.array([sx * 1.01 * s, sy * 1.01 * s, 1.0]) * 20.0
        rows_in, rows_out = matrix[0] @ inside, matrix[0] @ outside
        assert np.all(rows_in >= lower[0] - 1e-9) and np.all(rows_in <= upper[0] + 1e-9)
        assert np.any(rows_out > upper[0] + 1e-9)


def test_mujoco_holds_the_diamond_along_its_axes() -> None:
    """The diamond's corners, :math:`\\mu` along one tangent axis, hold in MuJoCo (its own
    diamond reaches :math:`\\mu_{sim} = 1` there)."""
    for axes in ((1.0, 0.0), (0.0, -1.0)):
        slide = _foot_slide(MU, axes=axes)
        assert slide < 2e-3, f"diamond corner {axes} slid {slide:.4f} m"


def test_the_diamond_rows_are_inside_the_cone() -> None:
    """The MPC's diamond rows accept its four corners and its edges' middles, refuse each
    1 % further out, and every force they accept (sampled) is inside the Coulomb cone."""
    from ridempc.mpc.friction import friction_pyramids
    from ridempc.trajopt.schedule import Contact

    index = np.array([[0, 1, 2]])
    matrix, lower, upper = friction_pyramids(
        index, 3, [[Contact.GROUND]], np.eye(3)[None], MU, max_force=100.0, shape="diamond"
    )
    corners = [(MU, 0.0), (-MU, 0.0), (0.0, MU), (0.0, -MU), (MU / 2, MU / 2), (-MU / 2, MU / 2)]
    for tx, ty in corners:
        inside = np.array([tx, ty, 1.0]) * 20.0
        outside = np.array([1.01 * tx, 1.01 * ty, 1.0]) * 20.0
        rows_in, rows_out = matrix[0] @ inside, matrix[0] @ outside
        assert np.all(rows_in >= lower[0] - 1e-9) and np.all(rows_in <= upper[0] + 1e-9)
        assert np.any(rows_out > upper[0] + 1e-9)
    rng = np.random.default_rng(0)
    forces = np.column_stack([rng.uniform(-1.0, 1.0, (2000, 2)), np.ones(2000)])
    kept = forces[np.all(pyramid_matrix(MU, "diamond") @ forces.T >= 0.0, axis=0)]
    assert len(kept) > 300
    assert np.all(np.hypot(kept[:, 0], kept[:, 1]) <= MU * kept[:, 2] + 1e-12)
    with pytest.raises(ValueError, match="shape 'round'"):
        pyramid_rows(np.eye(3), MU, "round")


def test_a_swinging_site_gets_no_force_in_the_diamond() -> None:
    """The WBC's rows of a site in the air, those it pins at zero, have only the zero force
    in both shapes (three independent rows on three unknowns)."""
    from ridempc.wbc.constraints import FrictionPyramidConstraint
    from ridempc.wbc.contacts import ContactSet
    from ridempc.wbc.layout import DecisionLayout

    layout = DecisionLayout(nv=6, n_sites=1, n_motors=0)
    for shape in ("box", "diamond"):
        constraint = FrictionPyramidConstraint(layout, MU, 0.0, 100.0, shape)
        block = constraint.compute_qp_constraint(
            None, None, ContactSet.on_ground(np.array([False]))
        )
        pinned = (block.lower == 0.0) & (block.upper == 0.0)
        rows = block.matrix[pinned][:, layout.force]
        assert rows.shape == (3, 3) and np.linalg.matrix_rank(rows) == 3, shape


def test_an_unknown_pyramid_shape_is_refused() -> None:
    from ridempc.errors import ConfigError
    from ridempc.mpc.pairs import load_mpc_pair

    with pytest.raises(ConfigError, match="field 'pyramid': unknown 'round'"):
        WbcSettings(pyramid="round")
    assert load_mpc_pair("cassie", "hovershoes").pyramid == "diamond"
    assert load_mpc_pair("cassie", "segway").pyramid == "box"
