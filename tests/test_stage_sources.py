"""The rider's drift sources, command sources and target stages alone
(:mod:`ridempc.mpc.stages.drifts`, :mod:`ridempc.mpc.stages.frame_follow`,
:mod:`ridempc.mpc.stages.manoeuvre_choice`, :mod:`ridempc.mpc.stages.wbc_targets`,
:mod:`ridempc.mpc.stages.shoes`), each given known readings."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.mpc.lean import LeanSteering
from ridempc.mpc.plan_book import STEPS_PER_S, PlanBook
from ridempc.mpc.stages.base import ControlTick, MpcTick
from ridempc.mpc.stages.drifts import LeanDrift, SteadyDrift
from ridempc.mpc.stages.feet_targets import FootTargets
from ridempc.mpc.stages.frame_follow import CommandedFrame
from ridempc.mpc.stages.manoeuvre_choice import ManoeuvreChoice
from ridempc.mpc.stages.shoes import ShoeUpdate
from ridempc.mpc.stages.turn import TurnSoFar
from ridempc.mpc.stages.wbc_targets import TargetsFromPlan
from ridempc.mpc.state_map import PlanarFrame
from ridempc.scenarios.scenario import Command
from ridempc.trajopt.schedule import Contact


def _tick(**fields: Any) -> MpcTick:
    """An MPC tick riding on the plan in force, balancing, unless ``fields`` say otherwise."""
    base: dict[str, Any] = {
        "estimate": SimpleNamespace(yaw_rate=0.0),
        "now": 1.0,
        "speed": 0.0,
        "balancing": True,
        "plan": None,
        "plan_time": 0.9,
        "frame_turn": 0.0,
        "held": False,
        "diagnostics": {},
    }
    base.update(fields)
    return MpcTick(**base)


# ------------------------------------------------------------------ drift sources


class _Observer:
    """A disturbance observer that records whether it was held."""

    def __init__(self) -> None:
        self.estimate = np.array([0.2, -0.5])
        self.holds: list[bool] = []

    def update(self, x0: Any, plan: Any, now: float, elapsed: float, *rest: Any) -> None:
        self.holds.append(rest[-1])

    def drift(self, nx: int) -> np.ndarray:
        out = np.zeros(nx)
        out[0] = self.estimate[0]
        return out


def test_the_steady_drift_is_estimated_only_while_the_rider_balances_on_its_plan() -> None:
    """Offset-free MPC: the steady disturbance is estimated while the rider holds or coasts
    on the plan it follows; held through a manoeuvre (its accelerations are no constant
    disturbance) and while the plan is not followed; its largest row in the diagnostics."""
    observer = _Observer()
    source = SteadyDrift(cast(Any, observer), 1.0 / 30.0)
    diagnostics: dict[str, float] = {}
    drift = source.drift(_tick(diagnostics=diagnostics), np.zeros(3))
    assert drift is not None and drift[0] == pytest.approx(0.2)
    source.drift(_tick(balancing=False), np.zeros(3))
    source.drift(_tick(held=True), np.zeros(3))
    assert observer.holds == [False, True, True]
    assert diagnostics["disturbance_max"] == pytest.approx(0.5)


def test_the_lean_drift_is_the_turning_frames_centrifugal_pull() -> None:
    """Riding, the frame turning with the board at :math:`\\hat\\omega` pulls the centre of
    mass outwards: a drift :math:`-v\\hat\\omega` [m/s^2] on its lateral rate; none
    standing."""
    lean = LeanSteering()
    source = LeanDrift(lean, vy=2)
    lean.update(0.0, 0.0, 0.0, speed=0.0)
    assert source.drift(_tick(speed=0.0), np.zeros(4)) is None
    speed, yaw_rate = 3.0, 0.2
    lean.update(0.0, 0.0, yaw_rate, speed=speed)
    diagnostics: dict[str, float] = {}
    estimate = SimpleNamespace(yaw_rate=yaw_rate)
    tick = _tick(speed=speed, estimate=estimate, diagnostics=diagnostics)
    drift = source.drift(tick, np.zeros(4))
    assert drift is not None
    np.testing.assert_allclose(drift, [0.0, 0.0, -speed * yaw_rate, 0.0])
    assert diagnostics["lean_offset"] == lean.offset


# ------------------------------------------------------------------ command sources


@dataclass
class _Map:
    """The library frame: records where it is asked to follow the board."""

    follows: list[dict[str, Any]] = field(default_factory=list)
    grounds: int = 0

    def follow_sideways(self, estimate: Any, pose: tuple[float, float, float], **kw: Any) -> None:
        self.follows.append({"pose": pose, **kw})

    def follow_ground(self, estimate: Any) -> None:
        self.grounds += 1

    def state(self, estimate: Any) -> np.ndarray:
        return np.array([0.0, 0.0, 0.05 - 2.0 * np.pi])  # x, y, a heading wrapped once


def _frame(
    rate: float, lean: Any = None, spread: Any = None, here: Any = None
) -> tuple[CommandedFrame, _Map]:
    turn = np.full(3, rate)
    commands = SimpleNamespace(roll_and_turn=lambda *args: (np.zeros(4), turn))
    state = np.zeros((1, 3)) if here is None else np.asarray(here, dtype=float)[None, :]
    mpc = SimpleNamespace(reference=SimpleNamespace(states_at=lambda t: state))
    layout = SimpleNamespace(
        names={}, headings=(2,), board_pose=lambda state: (state[0], state[1], state[2])
    )
    state_map = _Map()
    frame = CommandedFrame(
        cast(Any, commands),
        cast(Any, mpc),
        cast(Any, layout),
        cast(Any, state_map),
        TurnSoFar(),
        lean,
        None,
        spread,
        follows_heading=lean is not None,
    )
    return frame, state_map


def test_the_frame_follows_the_board_onto_the_turned_reference() -> None:
    """The commanded yaw rate :math:`\\omega^*` is integrated into the turn so far,
    :math:`\\psi^* = \\int \\omega^* dt`; the frame follows the board onto the reference's
    pose turned by :math:`\\psi^*`, all along its line while turning (across it only while
    riding straight), and the estimate's heading is unwrapped to the turned reference's."""
    frame, state_map = _frame(0.3)
    for now in (1.0, 1.5):
        roll, turn, x0 = frame(_tick(now=now), Command(), cast(Any, None), now, False, True)
    assert frame.turn.turned == pytest.approx(0.3 * 0.5)
    assert [f["pose"][2] for f in state_map.follows] == pytest.approx([0.0, 0.15])
    assert all(f["along"] for f in state_map.follows) and state_map.grounds == 2
    assert x0[2] == pytest.approx(0.05)  # the heading unwrapped near the turn
    straight, straight_map = _frame(0.0)
    straight(_tick(), Command(), cast(Any, None), 1.0, False, True)
    straight(_tick(), Command(), cast(Any, None), 1.0, True, True)  # coasting
    assert [f["along"] for f in straight_map.follows] == [False, True]


def test_the_segways_frame_turns_with_the_lean_and_the_shoes_onto_their_lines() -> None:
    """Where the rider cannot drive the board's yaw rate the frame's heading follows the
    board's, carried by the lean loop's turn rate; on the Hovershoes the frame follows
    platform 0 onto its line spread by the commanded lateral offset."""
    lean = LeanSteering()
    frame, state_map = _frame(0.0, lean=lean)
    command = Command(yaw_rate=0.25)
    frame(_tick(speed=3.0), command, cast(Any, None), 1.0, False, True)
    assert state_map.follows[0]["heading"] and state_map.follows[0]["yaw_rate"] == 0.25
    shoes = [0.0, 0.1, 0.0, 0.0, -0.1, 0.0]  # per shoe x, y, heading: side by side along x
    spread, spread_map = _frame(0.0, spread=((0, 1, 2), (3, 4, 5)), here=shoes)
    spread(_tick(), Command(lateral_offset=0.04), cast(Any, None), 1.0, False, True)
    assert spread_map.follows[0]["yaw_rate"] == 0.0
    assert spread_map.follows[0]["pose"] == pytest.approx((0.0, 0.14, 0.0))


class _Selector:
    """The pair's manoeuvres: ``wanted`` asked for, its phase matched at ``start``."""

    def __init__(self, wanted: Any, repushed: Any = None) -> None:
        self.wanted, self.repushed = wanted, repushed
        self.phases: list[float] = []

    def select(self, command: Any, manoeuvre: Any, now: float, speed: float) -> Any:
        return manoeuvre if self.wanted is None else self.wanted

    def repush(self, command: Any, manoeuvre: Any, now: float, speed: float) -> Any:
        return manoeuvre if self.repushed is None else self.repushed

    def phase_start(self, times: Any, speeds: Any, speed: float, now: float, *rest: Any) -> float:
        self.phases.append(speed)
        return now - 0.25


@dataclass(frozen=True)
class _Manoeuvre:
    kind: str
    target: float
    library_kind: str
    start: float = 0.0


def _choice(selector: _Selector) -> tuple[ManoeuvreChoice, list[tuple[str, float]]]:
    retargets: list[tuple[str, float]] = []
    reference = SimpleNamespace(times=np.zeros(2), states=np.zeros((2, 1)))
    mpc = SimpleNamespace(reference=reference, retarget=lambda k, t: retargets.append((k, t)))
    commands = SimpleNamespace(speed_command=lambda command, now: command)
    layout = SimpleNamespace(names={"vx": 0})
    pair = SimpleNamespace(start_speed=0.0)
    choice = ManoeuvreChoice(
        cast(Any, selector),
        cast(Any, mpc),
        cast(Any, layout),
        cast(Any, pair),
        None,
        cast(Any, commands),
    )
    return choice, retargets


def test_a_new_manoeuvre_retargets_the_mpc_and_joins_it_at_the_riders_speed() -> None:
    """The manoeuvre held is kept (None); a new one retargets the MPC to its library entry
    and starts where the reference's speed is the centre of mass's; a coasting rider that
    nothing else moves is asked whether to push again."""
    hold = _Manoeuvre("hold", 0.0, "hold")
    keep, retargets = _choice(_Selector(None))
    assert keep(hold, Command(), 1.0, 0.0, 0.0, coasting=False) is None and retargets == []
    speed_up = _Manoeuvre("accelerate", 1.0, "accelerate")
    selector = _Selector(speed_up)
    choice, retargets = _choice(selector)
    chosen = choice(hold, Command(velocity=1.0), 2.0, 0.4, 0.5, coasting=False)
    assert chosen is not None and chosen.kind == "accelerate" and chosen.start == 1.75
    assert retargets == [("accelerate", 1.0)] and selector.phases == [0.5]
    repush = _Manoeuvre("repush", 1.0, "repush")
    coast, retargets = _choice(_Selector(None, repushed=repush))
    assert coast(speed_up, Command(velocity=1.0), 3.0, 0.6, 0.6, coasting=False) is None
    pushed = coast(speed_up, Command(velocity=1.0), 3.0, 0.6, 0.6, coasting=True)
    assert pushed is not None and pushed.kind == "repush" and retargets == [("repush", 1.0)]


# ------------------------------------------------------------------ targets and observers


def test_the_targets_read_the_plan_at_its_age_and_the_feet_through_a_flight() -> None:
    """The plan is read at its age in MPC steps in the frame it was solved in; the feet
    stand or swing as scheduled, and in a flight none is in contact, each swinging after
    its platform with the flight's acceleration; the plan's site forces go to the WBC only
    where the library's contacts are its sites; each shoe's drag is its platform's
    acceleration."""
    reads: list[tuple[Any, float]] = []
    sites = np.full((4, 3), 10.0)
    wanted = SimpleNamespace(
        position=np.array([0.0, 0.0, 0.9]),
        orientation=np.array([1.0, 0.0, 0.0, 0.0]),
        forces=np.zeros((2, 3)),
        velocity=np.zeros(3),
        acceleration=np.zeros(3),
        angular_velocity=np.zeros(3),
        angular_acceleration=np.zeros(3),
        site_forces=sites,
    )

    def read_plan(plan: Any, frame: Any, age: float) -> Any:
        reads.append((frame, age))
        return wanted

    standing = FootTargets(np.ones(2), np.zeros((2, 3)), np.zeros((2, 3)), None)
    feet_targets = lambda support, t_ref, estimate, frame: standing  # noqa: E731
    book = PlanBook(None)
    book.plan, book.time, book.frame = cast(Any, object()), 1.0, PlanarFrame(0.2)
    support = (Contact.BOARD, Contact.BOARD)
    estimate = SimpleNamespace(boards=("shoe",))
    drag = np.array([-0.3, 0.0, 0.0])
    shoes = SimpleNamespace(drift=lambda boards: (drag,) * len(boards))
    targets = TargetsFromPlan(
        cast(Any, read_plan), cast(Any, feet_targets), None, cast(Any, shoes), False
    )
    out = targets(book, support, 0.5, cast(Any, estimate), 1.0 + 0.5 / STEPS_PER_S)
    assert reads == [(book.frame, pytest.approx(0.5))]
    assert out.site_forces is None and len(out.board_acceleration) == 1
    np.testing.assert_array_equal(out.board_acceleration[0], drag)
    assert np.all(out.contact == 1.0) and out.swing_acceleration is None
    flying = np.full((2, 3), 9.81)
    flight = SimpleNamespace(
        flying=True,
        feet=lambda feet, estimate: (
            FootTargets(np.zeros(2), feet.swing, feet.swing_velocity, None),
            flying,
        ),
    )
    in_flight = TargetsFromPlan(
        cast(Any, read_plan), cast(Any, feet_targets), cast(Any, flight), None, True
    )
    out = in_flight(book, support, 0.5, cast(Any, estimate), 1.0)
    assert not np.any(out.contact)
    np.testing.assert_array_equal(out.swing_acceleration, flying)
    assert out.board_acceleration == ()
    assert out.site_forces is not None
    np.testing.assert_array_equal(out.site_forces, sites)


def test_the_shoes_observer_reads_the_whole_body_qps_sites_and_forces() -> None:
    """After the whole-body QP, the shoes' observer takes each contact site's place and
    force from its output (where each foot stands along its shoe, and the shoe's drag)."""
    seen: list[Any] = []
    observer = SimpleNamespace(update=lambda *args: seen.append(args))
    wbc = SimpleNamespace(site_positions="places", site_forces="forces")
    tick = ControlTick(cast(Any, None), cast(Any, "estimate"), np.zeros(2), False, {}, wbc=wbc)
    ShoeUpdate(cast(Any, observer)).observe(tick)
    assert seen == [("estimate", "places", "forces")]
