"""The decision to straddle across replans: joined groups, the deciding range, hysteresis."""

from __future__ import annotations

import numpy as np

from ridempc.autonomy.course import Box
from ridempc.autonomy.evaluation import rasterise
from ridempc.autonomy.occupancy import GridFrame
from ridempc.autonomy.straddle import StraddleSettings, group_cells
from ridempc.autonomy.straddle_decision import StraddleTracker

FRAME = GridFrame((0.0, -2.0), 0.05, (120, 80))  # 6 m x 4 m
SETTINGS = StraddleSettings()
FAR = np.array([0.0, 0.0])  # 2.7 m from the box's near end: beyond the deciding range
NEAR = np.array([1.0, 0.0])


def _grid(box: Box, height: float) -> tuple[np.ndarray, np.ndarray]:
    occupied = rasterise(FRAME, [box])
    return occupied, np.where(occupied, height, -np.inf)


def test_a_box_seen_with_an_unhit_cell_is_one_group() -> None:
    occupied, height = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.1)), 0.15)
    i, j = np.nonzero(occupied)
    occupied[:, j.min() + 1] = False  # a line of unhit cells through the box, a cell wide
    loner = (i.max(), j.min())  # and a cell alone beyond it
    occupied[loner] = True
    _, separate = group_cells(occupied, 0)
    _, joined = group_cells(occupied, round(SETTINGS.join / FRAME.resolution))
    assert separate > 1 and joined == 1
    (straddle,) = StraddleTracker(SETTINGS).update(FRAME, occupied, height, NEAR).straddles
    assert straddle.cells[loner]


def test_a_low_box_far_away_is_lined_up_with_before_it_is_decided() -> None:
    wide = Box(center=(3.0, 0.0), size=(0.6, 0.4, 0.1))  # wider than max_width
    occupied, height = _grid(wide, 0.15)
    narrow_first = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.1)), 0.15)
    tracker = StraddleTracker(SETTINGS)
    assert len(tracker.update(FRAME, *narrow_first, FAR).straddles) == 1  # taken, not decided
    assert tracker.update(FRAME, occupied, height, NEAR).straddles == ()  # decided: too wide


def test_a_decided_straddle_holds_within_the_margins() -> None:
    narrow = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.1)), 0.15)
    wider = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.4, 0.1)), 0.15)  # within the margin
    taller = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.1)), 0.22)
    assert SETTINGS.max_width < 0.4 <= SETTINGS.max_width + SETTINGS.width_margin
    assert SETTINGS.max_height < 0.22 <= SETTINGS.max_height + SETTINGS.height_margin
    assert StraddleTracker(SETTINGS).update(FRAME, *wider, NEAR).straddles == ()
    assert StraddleTracker(SETTINGS).update(FRAME, *taller, NEAR).straddles == ()
    tracker = StraddleTracker(SETTINGS)
    assert len(tracker.update(FRAME, *narrow, NEAR).straddles) == 1
    assert len(tracker.update(FRAME, *wider, NEAR).straddles) == 1
    assert len(tracker.update(FRAME, *taller, NEAR).straddles) == 1
    too_tall = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.5)), 0.5)
    assert tracker.update(FRAME, *too_tall, NEAR).straddles == ()  # released
    assert tracker.update(FRAME, *wider, NEAR).straddles == ()  # and decided afresh


def test_a_far_speck_is_ignored_and_a_near_one_ridden_round() -> None:
    occupied, height = _grid(Box(center=(3.01, 0.01), size=(0.04, 0.04, 0.1)), 0.1)
    assert 0 < occupied.sum() < SETTINGS.min_cells
    far = StraddleTracker(SETTINGS).update(FRAME, occupied, height, FAR)
    assert far.straddles == () and (far.ignored == occupied).all()
    near = StraddleTracker(SETTINGS).update(FRAME, occupied, height, np.array([2.0, 0.0]))
    assert near.straddles == () and not near.ignored.any()


def test_a_tall_box_is_never_a_straddle_nor_ignored() -> None:
    occupied, height = _grid(Box(center=(3.0, 0.0), size=(0.6, 0.2, 0.5)), 0.5)
    for rider in (FAR, NEAR):
        decision = StraddleTracker(SETTINGS).update(FRAME, occupied, height, rider)
        assert decision.straddles == () and not decision.ignored.any()
