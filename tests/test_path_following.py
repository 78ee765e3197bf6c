"""A commanded path: its geometry, the cross-track-to-yaw-rate law closing on it, the
judge's figures, and steering commands a board cannot turn refused before a ride."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ridempc.cli import main
from ridempc.controllers.path_following import DISTANCE, path_yaw_rate
from ridempc.scenarios import resolve_scenario
from ridempc.scenarios.path import CirclePath, PathGeometry, SlalomPath
from ridempc.scenarios.path_metrics import gates_passed, path_metrics
from ridempc.scenarios.scenario import Scenario

CIRCLE = CirclePath(kind="circle", start=0.0, entry=2.0, radius=3.0)
SLALOM = SlalomPath(kind="slalom", start=0.0, entry=2.0, spacing=3.0, offset=0.4, gates=3)


def test_circle_geometry() -> None:
    geometry = PathGeometry(CIRCLE)
    centre = np.array([2.0, 3.0])
    for angle in (0.3, 2.0, 4.0):
        outside = centre + 3.1 * np.array([math.sin(angle), -math.cos(angle)])
        index = geometry.nearest(outside)
        cross, heading = geometry.errors(outside, index)
        assert cross == pytest.approx(-0.1, abs=1e-3)  # outside a left turn: to the right
        assert math.remainder(heading - angle, 2 * math.pi) == pytest.approx(0.0, abs=1e-2)
        assert geometry.curvature[index] == pytest.approx(1.0 / 3.0, rel=1e-2)
    assert geometry.errors(np.array([-3.0, 0.2]), geometry.nearest(np.array([-3.0, 0.2])))[
        0
    ] == pytest.approx(0.2)  # the lead-in along the x axis


def test_slalom_gates() -> None:
    geometry = PathGeometry(SLALOM)
    on_path = geometry.points[::10]
    assert gates_passed(SLALOM, on_path) == 3
    straight = np.column_stack([np.linspace(-1.0, 18.0, 200), np.zeros(200)])
    assert gates_passed(SLALOM, straight) == 0  # 0.4 m off each gate, 0.25 m allowed
    gates = SLALOM.gate_points()
    np.testing.assert_allclose(gates[:, 1], [0.4, -0.4, 0.4])
    np.testing.assert_allclose(np.diff(gates[:, 0]), 3.0)
    assert SLALOM.max_curvature == pytest.approx(0.4 * (math.pi / 3.0) ** 2)


def test_the_law_turns_towards_the_path() -> None:
    assert path_yaw_rate(0.0, 0.0, 0.2, 0.7, DISTANCE) == pytest.approx(0.14)  # v kappa
    assert path_yaw_rate(0.3, 0.0, 0.0, 0.7, DISTANCE) < 0.0  # left of it: turn right
    assert path_yaw_rate(0.0, 0.2, 0.0, 0.7, DISTANCE) < 0.0  # heading left of it: right


@pytest.mark.parametrize("path", [CIRCLE, SLALOM], ids=["circle", "slalom"])
def test_a_unicycle_under_the_law_closes_on_the_path(path) -> None:
    """Kinematics only: from 0.3 m off and 0.2 rad astray, the error settles within a few
    settling distances, at 0.7 m/s, with the curvature read at the rider's place."""
    geometry = PathGeometry(path)
    x, y, heading, speed, dt = -2.0, 0.3, 0.2, 0.7, 0.01
    index, errors = None, []
    for _ in range(int(20.0 / dt)):
        index = geometry.nearest(np.array([x, y]), index)
        cross, path_heading = geometry.errors(np.array([x, y]), index)
        errors.append(cross)
        omega = path_yaw_rate(
            cross,
            math.remainder(heading - path_heading, 2 * math.pi),
            float(geometry.curvature[index]),
            speed,
            DISTANCE,
        )
        x += speed * math.cos(heading) * dt
        y += speed * math.sin(heading) * dt
        heading += omega * dt
    late = np.abs(np.array(errors[int(10.0 / dt) :]))
    assert late.max() < 0.03


def test_path_metrics_from_a_log() -> None:
    """The path laid from the base's pose at the path's start (here at (5, 2), heading
    +y), the base riding 0.1 m to the left of it after that."""
    scenario = Scenario(name="p", duration=10.0, path=SLALOM)
    geometry = PathGeometry(SLALOM)
    local = geometry.points[geometry.points[:, 0] >= 0.0][::20] + np.array([0.0, 0.1])
    local[0] = 0.0
    rotation = np.array([[0.0, -1.0], [1.0, 0.0]])  # +90 degrees
    xy = np.array([5.0, 2.0]) + local @ rotation.T
    n = len(xy)
    log = {
        "time": np.linspace(0.0, 10.0, n),
        "base_position": np.column_stack([xy, np.zeros(n)]),
        "yaw": np.full(n, math.pi / 2),
    }
    figures = path_metrics(log, scenario)
    json.dumps(figures, allow_nan=False)  # summary.json takes them as they are
    assert figures["gates"] == 3 and figures["gates_passed"] == 3
    assert 0.09 < figures["cross_track_rmse"] <= 0.1 + 1e-6
    assert path_metrics(log, Scenario(name="q", duration=10.0)) == {}


def test_the_steering_scenarios_load() -> None:
    for name in ("yaw-steps", "yaw-steps-hold", "circle", "slalom", "circle-hold", "slalom-hold"):
        scenario = resolve_scenario(name, "skateboard")
        assert scenario.boards == ("skateboard",)
    held = resolve_scenario("yaw-steps-hold", "skateboard").push_off
    assert held is not None and held.hold  # pushed again while rolling
    circle = resolve_scenario("circle-hold", "skateboard")
    assert circle.push_off is not None and circle.push_off.hold and circle.path is not None
    slalom = resolve_scenario("slalom-hold", "skateboard")
    assert slalom.push_off is not None and slalom.push_off.hold
    assert slalom.path.spacing == 3.0 and slalom.path.gates == 6  # type: ignore[union-attr]
    assert not resolve_scenario("push-off-0.5", "skateboard").push_off.hold  # type: ignore[union-attr]
    assert resolve_scenario("circle", "skateboard").path.radius == 3.0  # type: ignore[union-attr]


def _sim(capsys, scenario: Path, out: Path) -> tuple[int, str]:
    try:
        code = main(
            ["sim", "--robot", "cyberdog2", "--board", "skateboard", "--controller", "pd"]
            + ["--scenario", str(scenario), "--out", str(out)]
        )
    except SystemExit as exc:
        code = int(exc.code or 0)
    return code, capsys.readouterr().err


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ("[[commands]]\nt = 0.0\nvelocity = 0.1\nyaw_rate = 0.2\n", "commands.0.yaw_rate"),
        (
            "[[commands]]\nt = 0.0\nvelocity = 0.7\n[[commands]]\nt = 1.0\nyaw_rate = 0.6\n",
            "commands.1.yaw_rate",
        ),
        (
            '[[commands]]\nt = 0.0\nvelocity = 0.7\n[path]\nkind = "circle"\nstart = 1.0\n'
            "entry = 1.0\nradius = 1.0\n",
            "path.radius",
        ),
        (
            '[[commands]]\nt = 0.0\nvelocity = 0.7\n[path]\nkind = "slalom"\nstart = 1.0\n'
            "entry = 1.0\nspacing = 1.0\noffset = 0.4\ngates = 2\n",
            "path.offset",
        ),
        ('[path]\nkind = "circle"\nstart = 1.0\nentry = 1.0\nradius = 3.0\n', "path.start"),
    ],
    ids=["slow", "beyond-roll", "tight-circle", "tight-slalom", "path-at-rest"],
)
def test_a_turn_the_skateboard_cannot_steer_exits_2(capsys, tmp_path, body, field) -> None:
    scenario = tmp_path / "turn.toml"
    scenario.write_text(f'name = "turn"\nduration = 5.0\n{body}')
    code, err = _sim(capsys, scenario, tmp_path / "out")
    assert code == 2
    assert err.startswith("ridempc: error:") and len(err.strip().splitlines()) == 1
    assert field in err and "allowed" in err
    assert not (tmp_path / "out").exists()  # nothing written


def test_a_ride_with_a_path_follows_it_and_reports_the_cross_track() -> None:
    """One second on the skateboard (the PD, standing: the board does not roll, so nothing
    is steered): the rider is wrapped in the path follower and the summary carries the
    path's figures."""
    import ridempc

    scenario = Scenario(
        name="short-path",
        duration=1.0,
        commands=({"t": 0.0, "velocity": 0.7},),  # type: ignore[arg-type]
        path=CirclePath(kind="circle", start=0.5, entry=1.0, radius=3.0),
    )
    summary = ridempc.ride("cyberdog2", "skateboard", "pd", scenario)
    assert summary["status"] == "ok"
    assert summary["cross_track_rmse"] < 0.02  # [m] standing on its start
    assert "gates" not in summary


def test_the_rider_is_told_the_turn_ahead_of_it() -> None:
    """On the circle's straight entry the law asks for no turn yet, but the rider it wraps is
    told (``turn_preview``) the path's turn once she reaches the circle at her speed."""
    from types import SimpleNamespace

    from ridempc.controllers.base import Controller
    from ridempc.controllers.path_following import PathFollowing

    class Still(Controller):
        def update(self, sensors, command):  # type: ignore[no-untyped-def, override]
            raise AssertionError("not ridden")

    inner = Still(None, "none")  # type: ignore[arg-type]  # no robot: never ridden
    follower = PathFollowing(inner, CIRCLE)
    assert inner.turn_preview == follower.turn_ahead
    vio = SimpleNamespace(
        stamp=1.0, position=(0.0, 0.0), velocity=(0.5, 0.0), yaw=0.0, yaw_rate=0.0
    )
    now = follower.yaw_rate(SimpleNamespace(time=1.0, vio=vio))  # type: ignore[arg-type]
    follower._yaw_rate = now
    assert now == pytest.approx(0.0, abs=1e-6)  # 2 m before the circle, on the line
    assert follower.turn_ahead(2.0) == pytest.approx(0.0, abs=1e-6)  # 0.5 m on: the line
    assert follower.turn_ahead(6.0) == pytest.approx(0.5 / 3.0, rel=0.05)  # on the circle
