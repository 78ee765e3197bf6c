"""The rotation helpers under their former home: :mod:`ridempc.rotations` holds them.

Kept so that code written against ``ridempc.estimation.rotations`` on other branches still
imports; new code imports :mod:`ridempc.rotations`.
"""

from __future__ import annotations

from ridempc.rotations import (
    matrix_of_rpy,
    matrix_to_quaternion,
    quaternion_to_matrix,
    rpy_of_matrix,
    wrap_angle,
    yaw_of,
)

__all__ = [
    "matrix_of_rpy",
    "matrix_to_quaternion",
    "quaternion_to_matrix",
    "rpy_of_matrix",
    "wrap_angle",
    "yaw_of",
]
