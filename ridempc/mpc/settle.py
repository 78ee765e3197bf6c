"""After a push-off: the reference settles the rider back over its four feet.

The skateboard library's entries end with the centre of mass 6.4-8.7 cm ahead of where it
stood at the start, over the four feet (nothing in the trajectory optimisation's cost keeps
it back: 0.3-1.0 m/s; 7.3-9.5 cm in the library before ``SkateOptions.liftoff_force``), and
a reference held at its last node (:func:`~ridempc.mpc.reference.steady_riding`) keeps the
rider there for the rest of the ride, its weight on its front feet and its rear feet light
enough to drift off a rolling deck (``docs/tuning.md``).

:func:`settle_over_feet` gives the reference an offset that grows after its end, over
``duration`` [s], by a smoothstep :math:`s(\\tau) = 3\\tau^2 - 2\\tau^3`,
:math:`\\tau = (t - T)/\\text{duration}` clipped to [0, 1]
(:meth:`~ridempc.mpc.reference.MotionReference.states_at`):

- the centre of mass moves along the deck, in the board's axes, back to where it stood at
  the start, :math:`\\Delta c_{xy} = R_z(\\psi_T)\\,(r_0 - r_T)` [m] with
  :math:`r = R_z(-\\psi)(c_{xy} - b_{xy})` its place on the board (heading :math:`\\psi`,
  origin :math:`b`); its height and the trunk's attitude stay the end's (the riding
  crouch);
- the joint angles follow, :math:`\\Delta q` [rad] such that every foot stays where it
  stood at the end, :math:`p_i(c_T + \\Delta c, \\theta_T, q_T + \\Delta q) = p_i(c_T,
  \\theta_T, q_T)` (:func:`~ridempc.trajopt.rigid_body.feet_world`, solved by
  least squares);
- the deck forces share the weight as at the start: the first interval's forces, turned
  to the final heading, in place of the last's, :math:`\\Delta f_i = R_z(\\psi_T -
  \\psi_0) f_{i,0} - f_{i,T}` [N].
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from ridempc.boards.canonical import BoardState, board_state_columns
from ridempc.errors import ConfigError
from ridempc.mpc.reference import MotionReference
from ridempc.trajopt.rigid_body import RigidBodyRobot, feet_world
from ridempc.trajopt.rotations import rotation_z

__all__ = ["FOOT_TOLERANCE", "settle_over_feet"]

Array = NDArray[np.float64]
FOOT_TOLERANCE: float = 1e-6  # [m] how far the settled joints may leave a foot
# Solved offsets by reference (its name, first and last nodes, forces, settle time): the
# least squares take 7-10 ms, and the rider retargets inside an MPC tick.
_SOLVED: dict[tuple[object, ...], tuple[Array, Array]] = {}


def settle_over_feet(
    reference: MotionReference,
    robot: RigidBodyRobot,
    duration: float,
    board_states: Mapping[str, BoardState],
) -> MotionReference:
    """``reference`` settling back over the feet after its end (module docstring).

    Args:
        reference: A reference on one board (states ``com_*``, the base's angles, ``q_*``
            and the board's x, y and heading).
        robot: The SRBKM robot of its states.
        duration: Time the settle takes after the end [s].
        board_states: What each board state is (:mod:`ridempc.boards.canonical`).

    Raises:
        ConfigError: The reference has no single board, its joints do not fit the robot,
            or no joint angles keep its feet where they ended (within ``FOOT_TOLERANCE``).
    """
    key = (
        robot.name,
        reference.name,
        reference.states[0].tobytes(),
        reference.states[-1].tobytes(),
        reference.inputs[0].tobytes(),
        reference.inputs[-1].tobytes(),
        float(duration),
    )
    solved = _SOLVED.get(key)
    if solved is None:
        solved = _SOLVED[key] = _offsets(reference, robot, board_states)
    states, inputs = solved
    return replace(
        reference,
        settle_states=states.copy(),
        settle_inputs=inputs.copy(),
        settle_time=float(duration),
    )


def _offsets(
    reference: MotionReference, robot: RigidBodyRobot, board_states: Mapping[str, BoardState]
) -> tuple[Array, Array]:
    """The settled offsets of the states and the inputs (module docstring).

    Raises:
        ConfigError: As :func:`settle_over_feet`.
    """
    names = reference.state_names
    joints = [k for k, n in enumerate(names) if n.startswith("q_")]
    layout = names[:4] == ("com_x", "com_y", "com_z", f"{robot.base}_roll")
    columns = board_state_columns(names, board_states)
    deck = [columns.get(BoardState(0, q)) for q in ("x", "y", "heading")]
    one_board = {state.platform for state in columns} == {0} and None not in deck
    if not (layout and one_board) or len(joints) != robot.n_joints:
        raise ConfigError(
            f"reference '{reference.name}': no single board and {robot.n_joints} joints "
            "to settle on"
        )
    i = names.index
    bx, by, yaw = (int(k) for k in deck if k is not None)
    first, last = reference.states[0], reference.states[-1]

    def on_board(x: Array) -> Array:
        offset = [x[i("com_x")] - x[bx], x[i("com_y")] - x[by], 0.0]
        return np.asarray(rotation_z(-x[yaw]) @ offset)

    heading = float(last[yaw])
    shift = rotation_z(heading) @ (on_board(first) - on_board(last))
    com, euler = last[0:3], last[3:6]  # eq. (1)'s layout: CoM, then roll, pitch, yaw
    q_end = last[joints]
    feet = np.concatenate(feet_world(robot, com, euler, q_end, np))

    def gap(q: Array) -> Array:
        return np.concatenate(feet_world(robot, com + shift, euler, q, np)) - feet

    solved = least_squares(gap, q_end, bounds=(robot.q_lower, robot.q_upper), xtol=1e-12)
    miss = float(np.max(np.abs(gap(solved.x))))
    if miss > FOOT_TOLERANCE:
        raise ConfigError(
            f"reference '{reference.name}': no joint angles keep the feet in place with the "
            f"centre of mass {100 * np.linalg.norm(shift):.1f} cm back (a foot misses by "
            f"{1000 * miss:.2f} mm)"
        )
    states = np.zeros(len(names))
    states[[i("com_x"), i("com_y")]] = shift[:2]
    states[joints] = solved.x - q_end
    inputs = np.zeros(reference.inputs.shape[1])
    turn = rotation_z(heading - float(first[yaw]))
    for rows in reference.force_index:
        inputs[rows] = turn @ reference.inputs[0, rows] - reference.inputs[-1, rows]
    return states, inputs
