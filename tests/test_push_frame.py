"""A stroke's reference forces and ground pyramid turned with the reference
(ridempc.mpc.push_frame)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ridempc.mpc.friction import ROWS_PER_CONTACT, friction_pyramids
from ridempc.mpc.push_frame import step_turns, with_turned_forces
from ridempc.trajopt.schedule import Contact
from tests.helpers import reference_problem

B, G = Contact.BOARD, Contact.GROUND


def _problem(schedule: list[tuple[Contact, ...]]):  # type: ignore[no-untyped-def]
    """Two contacts' forces (x, y, z) as the only inputs, the second pushing at the
    pyramid's corner on the ground where the schedule says."""
    n = len(schedule)
    index = np.array([[0, 1, 2], [3, 4, 5]])
    surfaces = np.repeat(np.eye(3)[None], 2, axis=0)
    g, lo, hi = friction_pyramids(index, 6, schedule, surfaces, 0.5, 200.0)
    problem = reference_problem(np.zeros(1), np.zeros((n + 1, 1)), 0.05, nu=6)
    forces = np.tile([1.0, 2.0, 30.0, 15.0, 15.0, 30.0], (n, 1))
    problem = replace(
        problem,
        input_reference=forces,
        constraint_matrix=g,
        constraint_lower=lo,
        constraint_upper=hi,
    )
    return problem, index


def test_the_turn_of_each_step_is_integrated_from_the_turn_so_far() -> None:
    turns = step_turns(np.array([0.2, 0.2, -0.4]), 1.0, 3, 0.5)
    np.testing.assert_allclose(turns, [1.0, 1.1, 1.2])


def test_a_stroke_is_the_entrys_stroke_in_the_turned_frame() -> None:
    """At a step with a foot on the ground every reference force is turned about the
    vertical, and the ground pyramid with it: every pyramid row takes the turned force to
    what it took the entry's (as feasible, the same rows binding)."""
    schedule = [(B, B), (B, G), (B, G)]
    problem, index = _problem(schedule)
    turns = np.array([0.3, 0.6, 0.9])
    turned = with_turned_forces(problem, index, schedule, turns)
    np.testing.assert_array_equal(turned.input_reference[0], problem.input_reference[0])
    for k in (1, 2):
        c, s = np.cos(turns[k]), np.sin(turns[k])
        for columns in index:
            fx, fy, fz = problem.input_reference[k, columns]
            expected = [c * fx - s * fy, s * fx + c * fy, fz]
            np.testing.assert_allclose(turned.input_reference[k, columns], expected)
        rows = slice(ROWS_PER_CONTACT, 2 * ROWS_PER_CONTACT)
        before = problem.constraint_matrix[k, rows] @ problem.input_reference[k]
        after = turned.constraint_matrix[k, rows] @ turned.input_reference[k]
        np.testing.assert_allclose(after, before, atol=1e-9)  # the same rows bind
        board = slice(0, ROWS_PER_CONTACT)  # the deck's pyramid follows the deck already
        np.testing.assert_array_equal(
            turned.constraint_matrix[k, board], problem.constraint_matrix[k, board]
        )


def test_no_stroke_or_no_turn_leaves_the_problem_alone() -> None:
    coasting = [(B, B), (B, B)]
    problem, index = _problem(coasting)
    assert with_turned_forces(problem, index, coasting, np.array([0.5, 0.6])) is problem
    pushing = [(B, G), (B, G)]
    problem, index = _problem(pushing)
    assert with_turned_forces(problem, index, pushing, np.zeros(2)) is problem
