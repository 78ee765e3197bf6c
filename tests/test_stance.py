"""The deck roll a four-foot stance can hold (ridempc.mpc.stance): the support lines from the
feet's places, bounds that leave a normal stance's roll wave alone and cut it on a stance
with a foot landed inward, held while a foot is off the deck."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ridempc.mpc.stance import StanceLimit, support_lines

FAR_SHARE = 0.2  # 2 x 8.7 N of the dog's 87 N
NORMAL = np.array([[0.19, 0.09], [0.19, -0.08], [-0.19, 0.08], [-0.19, -0.09]])
# push-off-1.0 seed 5 after its 4th stroke: the front-right foot 57 mm inward
INWARD = np.array([[0.19, 0.075], [0.19, -0.043], [-0.19, 0.078], [-0.19, -0.11]])


def test_support_lines_are_read_at_the_com():
    right, left = support_lines(NORMAL, 0.0)
    assert right == pytest.approx(-0.085) and left == pytest.approx(0.085)
    right, _ = support_lines(INWARD, 0.095)  # a quarter of the way from the front feet
    assert right == pytest.approx(-0.043 + 0.25 * (-0.11 + 0.043))


def test_normal_stance_leaves_the_roll_wave_alone():
    limit = StanceLimit(0.42)
    low, high = limit.bounds(NORMAL, np.array([0.0, -0.004]), 0.0, 0.03, FAR_SHARE)
    assert high > 0.1 and low < -0.1  # the wave's +-0.1 rad
    # y(phi) = y0 - s phi reaches the right line less the far feet's share at the bound
    keep = FAR_SHARE * 0.17
    assert -0.004 - 0.42 * high == pytest.approx(-0.085 + keep)


def test_inward_foot_cuts_the_roll_towards_it():
    limit = StanceLimit(0.42)
    low, high = limit.bounds(INWARD, np.array([0.0, -0.030]), 0.03, 0.03, FAR_SHARE)
    assert 0.0 < high < 0.07 and low < -0.1  # y0 -0.017 m, right line -0.077 m


def test_level_is_low_passed_reset_and_bounds_held():
    limit = StanceLimit(0.42, time_constant=0.3)
    limit.bounds(NORMAL, np.array([0.0, 0.0]), 0.0, 0.03, FAR_SHARE)
    limit.bounds(NORMAL, np.array([0.0, -0.01]), 0.0, 0.03, FAR_SHARE)
    assert limit.level == pytest.approx(-0.001)
    assert limit.last[1] == pytest.approx((-0.001 + 0.085 - FAR_SHARE * 0.17) / 0.42)
    limit.reset()
    assert limit.level is None and limit.last == (-math.inf, math.inf)


def test_lines_too_close_give_one_roll():
    limit = StanceLimit(0.42, margin=0.01)  # lines +-8.5 mm apart
    low, high = limit.bounds(NORMAL * 0.1, np.zeros(2), 0.0, 0.03, FAR_SHARE)
    assert low == high == pytest.approx(0.0)
