"""The library frame's transforms (:class:`~ridempc.mpc.state_map.PlanarFrame`), its rotation
and shift made once per frame: equal to the bit to the formula on every call, and a frame
moved (``dataclasses.replace``) computes its own."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ridempc.mpc.state_map import PlanarFrame


def _to_world(frame: PlanarFrame, p: np.ndarray) -> np.ndarray:
    """:math:`R_z(\\Delta\\psi) p + \\Delta p`, written out."""
    c, s = math.cos(frame.yaw), math.sin(frame.yaw)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return rotation.dot(p) + np.array([*frame.offset, frame.height])


def test_a_frame_read_again_and_moved_gives_the_formula_bit_for_bit() -> None:
    rng = np.random.default_rng(15)
    frame = PlanarFrame(0.7, (1.5, -0.25), 0.03)
    for _ in range(3):  # a moved frame: its own rotation and shift, not the first one's
        for _ in range(5):
            p = rng.normal(size=3)
            np.testing.assert_array_equal(frame.point_to_world(p), _to_world(frame, p))
            back = frame.point_to_library(frame.point_to_world(p))
            np.testing.assert_allclose(back, p, atol=1e-12)
            np.testing.assert_array_equal(frame.vector_to_library(p), frame._rotation(-1.0).dot(p))
        frame = replace(frame, yaw=float(rng.uniform(-3, 3)), offset=tuple(rng.normal(size=2)))
    assert frame == PlanarFrame(frame.yaw, frame.offset, frame.height)  # equal by its fields
