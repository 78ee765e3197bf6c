"""The deck roll a three-foot stance can hold (ridempc.mpc.stance_three): each foot's static
load from the centre of mass's barycentric coordinates, the roll towards the side that keeps
both feet, none the other way."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.mpc.stance_three import ThreeFootLimit, triangle_span

LEAST = 0.1  # 8.7 N of the dog's 87 N
# NORMAL of test_stance with the right rear foot in the air (a re-push's swing)
THREE = np.array([[0.19, 0.09], [0.19, -0.08], [-0.19, 0.08]])


def loads(feet: np.ndarray, com: np.ndarray) -> np.ndarray:
    """Each foot's share of the weight, from the three feet's force and moment balance."""
    return np.linalg.solve(np.vstack([feet.T, np.ones(3)]), np.append(com, 1.0))


def test_span_edges_leave_the_least_load():
    low, high = triangle_span(THREE, 0.0, LEAST, 0.0)
    assert 0.0 < low < high < 0.085
    assert loads(THREE, np.array([0.0, low])).min() == pytest.approx(LEAST)
    assert loads(THREE, np.array([0.0, high])).min() == pytest.approx(LEAST)
    assert loads(THREE, np.array([0.0, 0.5 * (low + high)])).min() > LEAST


def test_margin_and_crossing():
    low, high = triangle_span(THREE, 0.0, LEAST, 0.005)
    wide = triangle_span(THREE, 0.0, LEAST, 0.0)
    assert wide[0] < low < high < wide[1]
    low, high = triangle_span(THREE, 0.0, 0.4, 0.0)  # no place keeps 0.4 on each
    assert low == high


def test_roll_towards_the_two_feet_side_only():
    limit = ThreeFootLimit(0.42)
    centre = THREE.mean(axis=0)
    low, high = limit.bounds(THREE - centre, -centre, 0.0, 0.03, LEAST)
    # the left (+y) side keeps both feet: the deck rolls left edge down (negative) only
    assert -0.2 < low < -0.12 and -0.06 < high < -0.02
    limit.reset()
    assert limit.level is None
