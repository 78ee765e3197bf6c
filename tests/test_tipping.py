"""A Hovershoe does not tip over its tread: the whole-body QP's and the MPC's rows.

The shoe's 0.09 m tread under a deck 0.11 m high lets the feet's net sideways force reach
0.41 of their load; opposite sideways forces at a line foot's two ends (its twist) tip
nothing; a foot standing off the shoe's axis tips it sooner on its own side.
"""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.mpc.friction import friction_pyramids, pyramid_pattern
from ridempc.mpc.pairs import load_mpc_pair
from ridempc.mpc.rider import rolling_platforms
from ridempc.trajopt.schedule import Contact
from ridempc.wbc.constraints import PlatformTipConstraint
from ridempc.wbc.contacts import ContactSet
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.platforms import RollingPlatform
from ridempc.wheel_grip import WHEEL_GRIP

RATIO = 0.045 / 0.11  # half the shoe's tread over its deck's height


def test_the_shoes_tip_at_half_their_tread_over_their_height() -> None:
    shoes = rolling_platforms(load_board("hovershoes"))
    assert len(shoes) == 2
    for shoe in shoes:
        assert shoe.tread is not None
        assert 0.5 * shoe.tread / shoe.height == pytest.approx(RATIO)
    pair = load_mpc_pair("cassie", "hovershoes")
    assert [contacts for contacts, _ in pair.tipping] == [(0, 1), (2, 3)]
    assert all(ratio == pytest.approx(RATIO) for _, ratio in pair.tipping)
    assert load_mpc_pair("cassie", "segway").tipping == ()
    with pytest.raises(ValueError, match="tread"):
        RollingPlatform(mass=2.7, drive=400.0, tread=0.09, height=0.0)


def _wbc_rows(offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray, DecisionLayout]:
    layout = DecisionLayout(nv=6, n_sites=2, n_motors=0)
    contacts = ContactSet.on_ground(np.array([True, True]))
    tipping = ((np.array([0, 1]), offsets, np.full(2, RATIO)),)
    contacts = ContactSet(contacts.active, contacts.frame, contacts.acceleration, None, tipping)
    block = PlatformTipConstraint(layout, 1).compute_qp_constraint(None, None, contacts)
    assert np.all(block.lower == -np.inf)
    return block.matrix, block.upper, layout


def _holds(matrix: np.ndarray, upper: np.ndarray, layout: DecisionLayout, forces) -> bool:
    z = np.zeros(layout.size)
    z[layout.force] = np.asarray(forces, dtype=float).ravel()
    return bool(np.all(matrix @ z <= upper + 1e-9))


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_the_wbc_keeps_the_net_sideways_force_within_the_tread(side: float) -> None:
    matrix, upper, layout = _wbc_rows(np.zeros(2))
    load = 100.0  # [N] per site
    within = side * 0.99 * RATIO * load
    beyond = side * 1.01 * RATIO * load
    assert _holds(matrix, upper, layout, [[0, within, load], [0, within, load]])
    assert not _holds(matrix, upper, layout, [[0, beyond, load], [0, beyond, load]])
    twist = 0.9 * load  # opposite ends: no net sideways force
    assert _holds(matrix, upper, layout, [[0, twist, load], [0, -twist, load]])
    # a foot 2 cm to the left of the axis: a push to the right (on the robot: its force
    # on the shoe is to the left) tips it sooner, to the left later
    off, _, _ = _wbc_rows(np.full(2, 0.02 / 0.11))
    limit = RATIO * load
    assert not _holds(off, upper, layout, [[0, -0.9 * limit, load]] * 2)
    assert _holds(off, upper, layout, [[0, 1.1 * limit, load]] * 2)


def mpc_sideways_rows(yaw: float, grip: float | None = None):
    """The MPC's rows on one shoe turned by ``yaw`` [rad] (two contacts), its pattern's
    check, and a test of forces in the shoe's frame against its two sideways rows."""
    index = np.arange(6).reshape(2, 3)
    tipping = (((0, 1), RATIO),)
    c, s = np.cos(yaw), np.sin(yaw)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    kwargs = {} if grip is None else {"grip": grip}
    matrix, lower, upper = friction_pyramids(
        index,
        6,
        [[Contact.BOARD] * 2],
        np.stack([rotation] * 2),
        0.6,
        500.0,
        shape="diamond",
        tipping=tipping,
        **kwargs,
    )
    assert matrix.shape == (1, 12, 6)
    pattern = pyramid_pattern(index, 6, tipping)
    assert np.all((matrix[0] != 0.0) <= pattern)
    rows = slice(10, 12)

    def holds(local_forces) -> bool:
        world = (rotation @ np.asarray(local_forces, dtype=float).T).T.ravel()
        g = matrix[0, rows] @ world
        return bool(np.all(g <= upper[0, rows] + 1e-9) and np.all(g >= lower[0, rows]))

    return holds


def test_the_mpc_keeps_the_net_sideways_force_within_the_tread() -> None:
    # a turned platform, on a floor that grips beyond the tread: the tread alone
    holds = mpc_sideways_rows(0.3, grip=1.0)
    load = 100.0
    assert holds([[0.0, 0.99 * RATIO * load, load]] * 2)
    assert not holds([[0.0, -1.01 * RATIO * load, load]] * 2)
    assert holds([[0.0, 0.5 * load, load], [0.0, -0.5 * load, load]])  # a twist


def test_the_mpc_keeps_the_net_sideways_force_within_the_wheels_grip() -> None:
    """The default grip (:mod:`ridempc.wheel_grip`) is tighter than the tread: it gives
    first, on the same rows; a twist takes none of it."""
    holds = mpc_sideways_rows(-0.4)
    load = 100.0
    assert holds([[0.0, 0.99 * WHEEL_GRIP * load, load]] * 2)
    assert not holds([[0.0, -1.01 * WHEEL_GRIP * load, load]] * 2)
    assert holds([[0.0, 0.5 * load, load], [0.0, -0.5 * load, load]])
