"""A Hovershoe's wheel neither skids sideways nor spins: the whole-body QP's grip rows (the
MPC's sideways rows share its tipping rows: tests/test_tipping.py).

The feet's net sideways force on a shoe stays within the conservative floor grip
:math:`\\mu_g` of their load, whatever the feet's offsets across the shoe (which only the
tread's tipping cares about); a line foot's twist (opposite sideways forces at its ends)
takes none of it. The riding library's own plans stay inside it.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ridempc.mpc.pairs import load_mpc_pair
from ridempc.paths import motion_library_dir
from ridempc.wbc.constraints import WheelGripConstraint
from ridempc.wbc.contacts import ContactSet
from ridempc.wbc.layout import DecisionLayout
from ridempc.wbc.platforms import RollingPlatform
from ridempc.wheel_grip import WHEEL_GRIP

TIP = 0.045 / 0.11  # half the shoe's tread over its deck's height
LOAD = 100.0  # [N] per site


SHOE = RollingPlatform(mass=2.7, drive=447.3, tread=0.09, height=0.11, twist_damping=18.2)
# two sites 8 cm apart along a line foot on the shoe's axis (x forward, y to the left)
PLACES = np.array([[0.04, 0.0, 0.11], [-0.04, 0.0, 0.11]])


def _wbc_rows(offsets: np.ndarray, grip: float = WHEEL_GRIP, turn: float = 0.0):
    layout = DecisionLayout(nv=6, n_sites=2, n_motors=0)
    contacts = ContactSet.on_ground(np.array([True, True]))
    tipping = ((np.array([0, 1]), offsets, np.full(2, TIP)),)
    contacts = ContactSet(contacts.active, contacts.frame, contacts.acceleration, None, tipping)
    terms = SimpleNamespace(sites=SimpleNamespace(position=PLACES))
    targets = SimpleNamespace(angular_velocity=np.array([0.0, 0.0, turn]))
    constraint = WheelGripConstraint(layout, [SHOE, None], grip)
    block = constraint.compute_qp_constraint(terms, targets, contacts)
    assert block.matrix.shape == (4, layout.size)
    assert np.all(block.lower == -np.inf)

    def holds(forces) -> bool:
        z = np.zeros(layout.size)
        z[layout.force] = np.asarray(forces, dtype=float).ravel()
        return bool(np.all(block.matrix @ z <= block.upper + 1e-9))

    return holds


def test_the_grip_is_tighter_than_the_tread() -> None:
    assert 0.0 < WHEEL_GRIP < TIP  # else the tipping rows would already hold the wheel


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("offset", [0.0, 0.02 / 0.11, -0.02 / 0.11])
def test_the_wbc_keeps_the_net_sideways_force_within_the_grip(side: float, offset: float) -> None:
    holds = _wbc_rows(np.full(2, offset))  # a foot off the axis: the same grip either way
    within, beyond = side * 0.99 * WHEEL_GRIP * LOAD, side * 1.01 * WHEEL_GRIP * LOAD
    assert holds([[0, within, LOAD], [0, within, LOAD]])
    assert not holds([[0, beyond, LOAD], [0, beyond, LOAD]])
    assert holds([[0.5 * LOAD, 0, LOAD]] * 2)  # along the travel the wheel rolls
    # the shoes squeezed apart: each foot pushing its shoe outwards at 0.3 of its load
    assert not holds([[0, 0.3 * LOAD, LOAD]] * 2)


def _twist(torque: float) -> list[list[float]]:
    """Opposite sideways forces at the foot's two ends: a twist of ``torque`` [N m] on the
    shoe, no net sideways force."""
    side = torque / 0.08
    return [[0, -side, LOAD], [0, side, LOAD]]


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_wbc_twists_a_standing_shoe_no_harder_than_its_rims_hold(sign: float) -> None:
    rims = WHEEL_GRIP * 2 * LOAD * 0.045  # mu_g N w / 2 [N m]
    holds = _wbc_rows(np.zeros(2))
    assert holds(_twist(sign * 0.99 * rims))
    assert not holds(_twist(sign * 1.01 * rims))


def test_a_planned_turn_twists_as_hard_as_its_rims_slide() -> None:
    """At 0.5 rad/s the rims' damping takes 9.1 N m, which the turn may add."""
    rims = WHEEL_GRIP * 2 * LOAD * 0.045
    turning = _wbc_rows(np.zeros(2), turn=-0.5)
    assert turning(_twist(rims + 0.99 * 18.2 * 0.5))
    assert not turning(_twist(rims + 1.01 * 18.2 * 0.5))
    assert not turning([[0, 0.3 * LOAD, LOAD]] * 2)  # the sideways grip stays


def test_a_grippier_floor_allows_more() -> None:
    holds = _wbc_rows(np.zeros(2), grip=0.35)
    assert holds([[0, 0.3 * LOAD, LOAD]] * 2)


def test_the_riding_library_stays_within_the_grip() -> None:
    """The library's plans (turns included) ask less of each wheel than the grip allows, so
    the rows cut nothing the MPC's references want."""
    pair = load_mpc_pair("cassie", "hovershoes")
    folder = motion_library_dir() / "cassie-hovershoes"
    entries = sorted(folder.glob("*.npz"))
    assert entries
    for path in entries:
        with np.load(path) as entry:
            names, inputs = list(entry["input_names"]), entry["inputs"]
            states, state_names = entry["states"][:-1], list(entry["state_names"])
        for (contacts, _), prefix in zip(pair.tipping, pair.platform_prefixes, strict=True):
            heading = states[:, state_names.index(f"{prefix}psi")]
            force = [
                sum(inputs[:, names.index(f"f_{pair.contacts[i]}_{a}")] for i in contacts)
                for a in "xyz"
            ]
            sideways = -np.sin(heading) * force[0] + np.cos(heading) * force[1]
            assert np.all(np.abs(sideways) <= WHEEL_GRIP * force[2]), path.name
