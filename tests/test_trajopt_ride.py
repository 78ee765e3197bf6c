"""Cassie on the wheeled boards: the simplified rider, the boards' reduced models in CasADi,
and the ride problems (built, not solved)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ridempc.boards import load_board
from ridempc.boards.hovershoes.reduced import shoe_dynamics
from ridempc.boards.segway.reduced import segway_dynamics
from ridempc.errors import ConfigError
from ridempc.trajopt.pairs import EntrySpec, load_pair
from ridempc.trajopt.platforms import HovershoesBoard, SegwayBoard, platform_torques
from ridempc.trajopt.ride_pair import ride_models
from ridempc.trajopt.ride_problem import ride_layout, ride_rates
from ridempc.trajopt.rigid_body import GRAVITY

BOARDS = ("hovershoes", "segway")


@pytest.mark.parametrize("board", BOARDS)
def test_rider_stands_on_its_platforms(board: str) -> None:
    rider, wheeled = ride_models("cassie", board)
    assert rider.body.mass == pytest.approx(32.8226, rel=1e-4)
    assert rider.foot_of_contact == (0, 0, 1, 1)  # toe front/back, left then right
    assert np.all((rider.leg_length > 0.8) & (rider.leg_length < 1.0))
    layout = ride_layout(rider, wheeled)
    assert np.allclose(layout["places"][:, 2], 0.0, atol=5e-3)  # soles on the deck tops
    assert layout["com_height"] > wheeled.top + 0.8
    # Contacts fit on their platforms (Segway 0.26 x 0.38 m, Hovershoe decks 0.28 m long).
    assert np.all(np.abs(layout["places"][:, 0]) < 0.14)


@pytest.mark.parametrize("board", BOARDS)
def test_board_rates_are_the_reduced_model(board: str) -> None:
    rider, wheeled = ride_models("cassie", board)
    rates = ride_rates(rider, wheeled)
    layout = ride_layout(rider, wheeled)
    rng = np.random.default_rng(2)
    x = np.concatenate([[0, 0, layout["com_height"]], rng.normal(0, 0.05, 9)])
    xb = wheeled.steady(0.7, layout["origins"]) + rng.normal(0, 0.02, len(wheeled.state_names))
    x = np.concatenate([x, xb])
    forces = rng.uniform(10, 100, (rider.n_contacts, 3))
    extra = rng.uniform(-0.1, 0.1, len(wheeled.input_names))
    u = np.concatenate([forces.ravel(), extra])
    out = np.asarray(rates(x, u, 0.0)).ravel()
    points = [
        np.asarray(wheeled.pose(ca.DM(xb), p)[1] + wheeled.pose(ca.DM(xb), p)[0] @ place).ravel()
        for place, p in zip(layout["places"], layout["platform_of"], strict=True)
    ]
    torques = platform_torques(
        wheeled,
        ca.DM(xb),
        [ca.DM(f) for f in forces],
        [ca.DM(p) for p in points],
        layout["platform_of"],
    )
    torques = [(float(a), float(b)) for a, b in torques]
    if isinstance(wheeled, HovershoesBoard):
        expected = np.concatenate(
            [shoe_dynamics(xb[7 * i : 7 * i + 7], torques[i], wheeled.reduced) for i in range(2)]
        )
        # eq. (8) on the bare shoe, pushed by the rider along the platform's x axis
        for i in range(2):
            heading, theta = xb[7 * i + 2], xb[7 * i + 3]
            mine = [k for k, p in enumerate(layout["platform_of"]) if p == i]
            along = np.cos(heading) * forces[mine, 0] + np.sin(heading) * forces[mine, 1]
            push = -float(np.sum(np.cos(theta) * along - np.sin(theta) * forces[mine, 2]))
            expected[7 * i + 6] = (wheeled.reduced.c4 * theta + push) / wheeled.shoe_mass
    else:
        assert isinstance(wheeled, SegwayBoard)
        expected = np.array(segway_dynamics(xb, (torques[0][0], extra[0]), wheeled.reduced))
    assert np.allclose(out[12:], expected, atol=1e-10)
    # The rider feels the forces: total force over the mass, plus gravity.
    assert np.allclose(out[6:9], forces.sum(axis=0) / rider.body.mass + [0, 0, -GRAVITY])


def test_pitch_torque_sign_leans_to_accelerate() -> None:
    """Pressing the toes (front contacts) pitches the shoes nose down, which speeds them up."""
    rider, wheeled = ride_models("cassie", "hovershoes")
    layout = ride_layout(rider, wheeled)
    xb = wheeled.steady(0.0, layout["origins"])
    points = [
        wheeled.pose(ca.DM(xb), p)[1] + wheeled.pose(ca.DM(xb), p)[0] @ ca.DM(place)
        for place, p in zip(layout["places"], layout["platform_of"], strict=True)
    ]
    front = [ca.DM([0, 0, 120.0]) if "front" in c else ca.DM([0, 0, 40.0]) for c in rider.contacts]
    torques = platform_torques(wheeled, ca.DM(xb), front, points, layout["platform_of"])
    assert all(float(t[0]) > 0 for t in torques)


def test_segway_steady_state_is_steady() -> None:
    _, wheeled = ride_models("cassie", "segway")
    assert isinstance(wheeled, SegwayBoard)
    state = wheeled.steady(1.5, np.zeros((1, 2)))
    rates = segway_dynamics(state, (wheeled.steady_torque(1.5), 0.0), wheeled.reduced)
    assert np.allclose(rates[3:], 0.0, atol=1e-9)


@pytest.mark.parametrize("board", BOARDS)
@pytest.mark.parametrize("kind", ["accelerate", "stop", "turn"])
def test_ride_problems_build(board: str, kind: str) -> None:
    pair = load_pair("cassie", board)
    problem = pair.build(EntrySpec(kind, 0.5))
    n = problem.n_intervals
    assert problem.variables.shape[0] == n * (2 * problem.nx + problem.nu) + problem.nx
    assert problem.metadata["kind"] == kind
    start = problem.lbw[: problem.nx]
    assert np.allclose(start, problem.ubw[: problem.nx])  # fixed initial state
    speed = problem.state_names.index("vx")
    assert start[speed] == pytest.approx(0.0 if kind == "accelerate" else 0.5)


@pytest.mark.parametrize("board", BOARDS)
def test_ride_targets_beyond_the_speed_limit_are_refused(board: str) -> None:
    pair = load_pair("cassie", board)
    with pytest.raises(ConfigError, match="speed limit"):
        pair.check(EntrySpec("accelerate", 20.0))
    with pytest.raises(ConfigError, match="no 'backflip'"):
        pair.check(EntrySpec("backflip", 0.5))
    assert load_board(board) is not None


def test_a_pairs_own_options_set_its_manoeuvre_times() -> None:
    """A speed change takes ``2 settle + manoeuvre_base + seconds_per_speed * dv``: the
    pairs' own defaults (0.4 s + 0.8 s per m/s, not RideOptions' 1 s + 2 s per m/s) make an
    accelerate to 1.0 m/s 2.2 s long, on the Segway on a grid of 0.0125 s; an entry's own
    options override the pair's."""
    for board, step in (("hovershoes", 0.025), ("segway", 0.0125)):
        problem = load_pair("cassie", board).build(EntrySpec("accelerate", 1.0))
        assert problem.times[-1] == pytest.approx(2.2), board
        assert problem.metadata["options"]["manoeuvre_base"] == 0.4
        assert problem.times[1] - problem.times[0] == pytest.approx(step), board
    hovershoes = load_pair("cassie", "hovershoes")
    slow = hovershoes.build(EntrySpec("accelerate", 1.0, {"seconds_per_speed": 2.0}))
    assert slow.times[-1] == pytest.approx(3.4)
    with pytest.raises(ConfigError, match="unknown ride option 'base'"):
        hovershoes.check(EntrySpec("accelerate", 1.0, {"base": 1.0}))
