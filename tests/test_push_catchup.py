"""A re-push's lag made up over its ground time (ridempc/mpc/push_catchup.py)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.push_catchup import MAX_CATCH_UP, catch_up, ground_time_left
from ridempc.trajopt.schedule import Contact
from tests.helpers import bare_problem

B, G, S = Contact.BOARD, Contact.GROUND, Contact.SWING


def _problem(contacts: list[tuple[Contact, ...]], dt: float = 0.05, nx: int = 3) -> MpcProblem:
    """A problem of ``len(contacts)`` steps (its dynamics and reference unused)."""
    n = len(contacts)
    return bare_problem(np.zeros(nx), np.zeros((n + 1, nx)), dt, tuple(contacts))


def test_the_lag_is_made_up_only_while_a_foot_is_on_the_ground() -> None:
    """Swing, six ground steps, swing: the extra speed rises only across the ground steps
    (only the pushing foot adds momentum) and reaches the lag once the ground time left is
    spent, then holds."""
    contacts = [(B, S)] * 3 + [(B, G)] * 6 + [(B, S)] * 4
    extra = catch_up(_problem(contacts), 0.1, ground_left=0.3)
    assert len(extra) == len(contacts) + 1
    np.testing.assert_allclose(extra[:4], 0.0)  # before the touchdown: coasting as planned
    np.testing.assert_allclose(np.diff(extra[3:10]), 0.1 * 0.05 / 0.3)  # evenly over the push
    np.testing.assert_allclose(extra[9:], 0.1)  # made up by the stroke's end, then held


def test_only_the_share_of_the_ground_left_within_the_horizon_is_asked() -> None:
    """Half the entry's ground time within the horizon: half the lag asked back."""
    contacts = [(B, G)] * 4 + [(B, S)] * 4
    extra = catch_up(_problem(contacts), 0.1, ground_left=0.4)
    assert extra[-1] == pytest.approx(0.05)


def test_no_lag_no_ground_left_or_a_lead_asks_nothing() -> None:
    problem = _problem([(B, G)] * 5)
    for lag, left in ((0.0, 0.25), (-0.2, 0.25), (0.1, 0.0)):
        np.testing.assert_array_equal(catch_up(problem, lag, left), 0.0)
    np.testing.assert_array_equal(catch_up(_problem([(B, S)] * 5), 0.1, 0.25), 0.0)


def test_a_lag_beyond_one_strides_gain_is_made_up_only_to_that_gain() -> None:
    extra = catch_up(_problem([(B, G)] * 5), 1.0, ground_left=0.25)
    assert extra.max() == pytest.approx(MAX_CATCH_UP)


def test_the_ground_time_left_counts_the_entrys_pushes_from_the_moment() -> None:
    """On the committed re-push to 0.7 m/s: all its pushes at its start, none after the
    last one."""
    from ridempc.mpc.reference import select_reference

    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    ground = [j for j, step in enumerate(reference.schedule) if Contact.GROUND in step]
    assert ground_time_left(reference, 0.0) == pytest.approx(len(ground) * reference.dt)
    after = float(reference.times[0]) + (ground[-1] + 1) * reference.dt
    assert ground_time_left(reference, after) == 0.0
    middle = float(reference.times[0]) + ground[0] * reference.dt
    assert ground_time_left(reference, middle) == pytest.approx(len(ground) * reference.dt)


def test_the_extra_speed_moves_the_places_by_its_integral() -> None:
    """shifted_speeds with a per-node extra speed: each speed gains the shift plus its
    node's extra, each place the sum of the steps' speeds times the step."""
    from ridempc.mpc.manoeuvre import StateLayout
    from ridempc.mpc.pairs import load_mpc_pair
    from ridempc.mpc.push_gain import shifted_speeds
    from ridempc.mpc.reference import select_reference

    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    layout = StateLayout.from_pair(reference.state_names, load_mpc_pair("cyberdog2", "skateboard"))
    names = layout.names
    n, dt = 12, 0.05
    window = reference.states_at(1.2 + dt * np.arange(n + 1))
    problem = _problem([(B, G)] * n, dt=dt, nx=window.shape[1])
    problem = replace(problem, state_reference=window)
    extra = np.linspace(0.0, 0.06, n + 1)
    slower = window[0, names["board_v"]] - 0.1
    change = shifted_speeds(problem, layout, slower, extra).state_reference - window
    np.testing.assert_allclose(change[:, names["board_v"]], -0.1 + extra)
    heading = window[:, names["board_yaw"]]
    np.testing.assert_allclose(change[:, names["vx"]], (-0.1 + extra) * np.cos(heading))
    steps = np.diff(change[:, names["com_x"]])
    np.testing.assert_allclose(steps, (-0.1 + extra[:-1]) * np.cos(heading[:-1]) * dt, atol=1e-12)


def test_a_board_at_its_rolling_start_is_asked_no_more_than_the_entry_plans() -> None:
    """The lag asked back is at most how far the board is below the entry's rolling start:
    none at or above it (the strokes are laid for that board), the smaller of the two
    below it, and it fades out continuously as the board reaches it."""
    from ridempc.mpc.manoeuvre import StateLayout
    from ridempc.mpc.pairs import load_mpc_pair
    from ridempc.mpc.push_catchup import stroke_catch_up
    from ridempc.mpc.reference import select_reference

    reference = select_reference("cyberdog2", "skateboard", "repush", 0.7)
    layout = StateLayout.from_pair(reference.state_names, load_mpc_pair("cyberdog2", "skateboard"))
    n, dt = 12, 0.05
    ground = [j for j, step in enumerate(reference.schedule) if Contact.GROUND in step]
    t = float(reference.times[0]) + ground[0] * reference.dt  # the first push's touchdown
    window = reference.states_at(t + dt * np.arange(n + 1))
    planned = float(window[0, layout.names["board_v"]])
    problem = replace(_problem([(B, G)] * n, dt=dt, nx=window.shape[1]), state_reference=window)
    share = n * dt / ground_time_left(reference, t)

    def asked(speed: float, start: float) -> float:
        return float(stroke_catch_up(problem, layout, reference, t, speed, start)[-1])

    slow = planned - 0.1  # 0.1 m/s behind the entry
    assert asked(slow, slow) == 0.0 and asked(slow, slow - 0.05) == 0.0
    assert asked(slow, slow + 0.05) == pytest.approx(0.05 * share)  # below the start by less
    assert asked(slow, slow + 0.5) == pytest.approx(0.1 * share)  # the lag, smaller
