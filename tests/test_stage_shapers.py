"""The rider's problem shapers alone (:mod:`ridempc.mpc.stages.board_shapers`,
:mod:`ridempc.mpc.stages.manoeuvre_shapers`): each given a known problem and what the loop
had at its tick changes the problem as its docstring says, and only where it should."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any, cast

import numpy as np
import pytest

from ridempc.mpc.lean import CROUCH_DELAY, CROUCH_SECONDS, Crouch
from ridempc.mpc.manoeuvre import HOLD, StateLayout
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.stages.board_shapers import CrouchShaper, HeldForces, LeanShaper, ShoeLines
from ridempc.mpc.stages.build import BuildInputs
from ridempc.mpc.stages.manoeuvre_shapers import Coasting, RepushBlend, RollCommand, Turn
from ridempc.trajopt.schedule import Contact
from tests.helpers import reference_problem

DT = 1.0 / 30.0  # [s] the MPC's step


def _problem(
    window: np.ndarray, nu: int = 2, contacts: tuple[tuple[Contact, ...], ...] = ()
) -> MpcProblem:
    """An MPC problem around the state reference ``window``, from its first state."""
    return reference_problem(window[0].copy(), window, DT, nu, contacts, bound=100.0)


def _inputs(**fields: Any) -> BuildInputs:
    """What the loop had at its tick: a hold at rest unless ``fields`` say otherwise."""
    base: dict[str, Any] = dict.fromkeys(BuildInputs._fields)
    base.update(
        t_ref=-1.0,
        now=0.0,
        speed=0.0,
        roll=np.zeros(4),
        turn=np.zeros(3),
        turned=0.0,
        coasting=False,
        switched=False,
        manoeuvre=(HOLD, 0.0),
        contacts=(),
        began=False,
        lateral_offset=0.0,
    )
    base.update(fields)
    return BuildInputs(**base)


# ------------------------------------------------------------------ the board's


def test_the_crouch_lowers_the_centre_of_mass_over_its_ramp() -> None:
    """The reference's centre of mass (row ``com_z`` only) goes down by the crouch's drop
    :math:`\\Delta h` times the ramp's share, 0 until ``CROUCH_DELAY`` after the first
    problem and 1 from ``CROUCH_SECONDS`` after that."""
    drop, com_z = -0.12, 1
    shaper = CrouchShaper(Crouch(drop), com_z)
    window = np.ones((4, 3))
    assert shaper(_problem(window), _inputs(now=2.0)).state_reference is window  # its start
    half = 2.0 + CROUCH_DELAY + 0.5 * CROUCH_SECONDS
    lowered = shaper(_problem(window), _inputs(now=half)).state_reference
    np.testing.assert_allclose(lowered[:, com_z], 1.0 + 0.5 * drop)
    np.testing.assert_array_equal(np.delete(lowered, com_z, axis=1), 1.0)
    full = shaper(_problem(window), _inputs(now=half + CROUCH_SECONDS)).state_reference
    np.testing.assert_allclose(full[:, com_z], 1.0 + drop)


class _Lean:
    """A lean loop that records what it is asked to lay over the reference."""

    def __init__(self, offset: float) -> None:
        self.offset = offset
        self.leaned: list[Any] = []
        self.turned = 0

    def lean(self, problem: MpcProblem, com_y: int, vy: int, balance: Any) -> MpcProblem:
        self.leaned.append((com_y, vy, balance))
        return problem

    def turn(self, problem: MpcProblem, layout: Any) -> MpcProblem:
        self.turned += 1
        return problem


def test_the_lean_finds_its_balance_once_a_manoeuvre_and_always_turns() -> None:
    """The forces' balance per metre of the lean's offset (a static shift of ``com_y``) is
    found at a manoeuvre's first lean and kept through it; a lean of zero needs none; the
    frame's turn is laid over the reference at every tick of a lean loop."""
    shifts: list[tuple[float, int]] = []
    names = {"com_y": 3, "vy": 7}

    def static_shift(t: float, changed: int, rider: Any) -> str:
        shifts.append((t, changed))
        return f"balance {len(shifts)}"

    mpc = SimpleNamespace(static_shift=static_shift)
    layout = SimpleNamespace(names=names, rider_states=(3, 4))
    shaper = LeanShaper(cast(Any, mpc), cast(Any, layout))
    problem = _problem(np.zeros((3, 8)))
    assert shaper(problem, _inputs()) is problem  # no lean loop: nothing to lay over
    still = _Lean(0.0)
    shaper(problem, _inputs(lean=still))
    assert still.leaned == [] and still.turned == 1 and shifts == []
    lean = _Lean(0.02)
    for t in (1.0, 1.5):
        shaper(problem, _inputs(lean=lean, t_ref=t, manoeuvre=("accelerate", 1.0)))
    shaper(problem, _inputs(lean=lean, t_ref=0.2, manoeuvre=("accelerate", 2.0)))
    assert shifts == [(1.0, 3), (0.2, 3)]
    assert [b for *_, b in lean.leaned] == ["balance 1", "balance 1", "balance 2"]
    assert lean.leaned[0][:2] == (3, 7) and lean.turned == 3


class _Shoes:
    """The shoes' observer, frozen: no foot's place to shift and no drag."""

    def shift_reference(self, states: np.ndarray, columns: Any) -> np.ndarray:
        return states

    def speed_drift(self, c: np.ndarray, dt: float, speeds: Any) -> np.ndarray:
        return c


def test_the_shoes_lines_spread_apart_across_their_headings() -> None:
    """A commanded lateral offset :math:`d` moves each shoe's reference :math:`d` further
    from the shoes' mean, across its heading (two shoes heading along x at
    :math:`y = \\pm 0.1` m go to :math:`\\pm(0.1 + d)`); without the shoes' observer the
    problem is left as it is."""
    columns = ((0, 1, 2, 3), (4, 5, 6, 7))  # per shoe: x, y, heading, speed
    window = np.zeros((3, 8))
    window[:, 1], window[:, 5] = 0.1, -0.1
    shaper = ShoeLines(columns, guidance=False)
    problem = _problem(window)
    assert shaper(problem, _inputs()) is problem
    spread = shaper(problem, _inputs(shoes=_Shoes(), lateral_offset=0.05)).state_reference
    np.testing.assert_allclose(spread[:, 1], 0.15)
    np.testing.assert_allclose(spread[:, 5], -0.15)
    np.testing.assert_array_equal(spread[:, [0, 2, 3, 4, 6, 7]], 0.0)


def test_a_swing_holds_the_standing_feet_forces_to_the_last_plans() -> None:
    """While a foot swings and the contacts are the last tick's, the first step's board
    force :math:`u_0` is drawn to the last plan's :math:`u_p` with weight
    :math:`1/s^2` (``swing_force_step`` :math:`s` [N]): the step-0 reference becomes
    :math:`(R u^{ref} + u_p / s^2) / (R + 1/s^2)`; the swinging foot's force is free, and
    a contact change, no swing or no plan leave the problem as it is."""
    step = 5.0
    contacts = (Contact.SWING, Contact.BOARD)
    mpc = SimpleNamespace(reference=SimpleNamespace(force_index=np.array([[0], [1]])))
    shaper = HeldForces(cast(Any, mpc), step)
    problem = _problem(np.zeros((3, 2)), contacts=(contacts, contacts))
    last = np.array([40.0, 60.0])
    held = shaper(problem, _inputs(first_input=last, contacts=contacts))
    weight = 1.0 / step**2
    assert held.input_reference[0, 1] == pytest.approx(weight * 60.0 / (1.0 + weight))
    assert held.input_reference[0, 0] == 0.0 and np.all(held.input_reference[1] == 0.0)
    np.testing.assert_allclose(np.asarray(held.input_weights)[0], [1.0, 1.0 + weight])
    standing = (Contact.BOARD, Contact.BOARD)
    for inputs, shaped in (
        (_inputs(first_input=None, contacts=contacts), problem),
        (_inputs(first_input=last, contacts=standing), problem),
    ):
        assert shaper(shaped, inputs) is shaped
    still = _problem(np.zeros((3, 2)), contacts=(standing, standing))
    assert shaper(still, _inputs(first_input=last, contacts=standing)) is still


# ------------------------------------------------------------------ the manoeuvre's


@pytest.fixture(scope="module")
def skate() -> tuple[Any, StateLayout]:
    """The CyberDog2's skateboard push-off reference and its state layout."""
    from ridempc.mpc.pairs import load_mpc_pair
    from ridempc.mpc.reference import select_reference

    reference = select_reference("cyberdog2", "skateboard", "accelerate", 0.7)
    pair = load_mpc_pair("cyberdog2", "skateboard")
    return reference, StateLayout.from_pair(reference.state_names, pair)


def _window(reference: Any, t0: float, n: int = 6) -> np.ndarray:
    return np.array(reference.states_at(t0 + DT * np.arange(n + 1)))


def test_the_turn_turns_the_headings_by_the_commanded_rates(skate) -> None:
    """At a commanded yaw rate :math:`\\omega^*` every heading at node :math:`k` gains
    :math:`\\psi_0 + k\\,\\omega^* \\Delta t` (:math:`\\psi_0` the turn so far) and every
    yaw rate :math:`\\omega^*`; with no rate and no turn the problem is left as it is."""
    reference, layout = skate
    window = _window(reference, 1.0)
    problem, turn = _problem(window), Turn(layout)
    assert turn(problem, _inputs(t_ref=1.0)) is problem
    rate, turned = 0.4, 0.1
    n = len(window) - 1
    shaped = turn(problem, _inputs(t_ref=1.0, turn=np.full(n, rate), turned=turned))
    gained = turned + rate * DT * np.arange(n + 1)
    for i in layout.headings:
        np.testing.assert_allclose(shaped.state_reference[:, i] - window[:, i], gained)
    yaw_rate = layout.names["wz"]
    np.testing.assert_allclose(shaped.state_reference[:, yaw_rate] - window[:, yaw_rate], rate)


def test_the_commanded_roll_is_laid_over_the_deck_and_the_rider_balanced(skate) -> None:
    """A commanded deck roll :math:`\\phi^*` sets the reference's ``board_roll`` at every
    node, and the rider's states move by the statics of that roll (the MPC's static
    shift, here a unit shift of one rider state per radian); no roll, no change."""
    reference, layout = skate
    names = layout.names
    nx = len(reference.state_names)
    knee = names["q_FL_knee"]
    unit = np.zeros(nx)
    unit[knee] = 1.0
    shift = SimpleNamespace(states=unit, inputs=np.zeros(2), velocities=np.zeros(nx))
    asked: list[int] = []
    mpc = SimpleNamespace(static_shift=lambda t, changed, rider: asked.append(changed) or shift)
    roller = RollCommand(cast(Any, mpc), layout)
    window = _window(reference, 1.0)
    problem = _problem(window)
    n = len(window)
    assert roller(problem, _inputs(t_ref=1.0, roll=np.zeros(n))) is problem and asked == []
    roll = 0.05
    shaped = roller(problem, _inputs(t_ref=1.0, roll=np.full(n, roll)))
    np.testing.assert_allclose(shaped.state_reference[:, names["board_roll"]], roll)
    moved = shaped.state_reference[:, knee] - window[:, knee]
    np.testing.assert_allclose(moved, roll - window[:, names["board_roll"]], atol=1e-12)
    assert asked == [names["board_roll"]]


def test_a_coasting_board_sets_the_reference_to_its_speed(skate) -> None:
    """Coasting, the reference's board and body speeds are scaled to the board's speed
    :math:`v` (:math:`r = v / v_{ref}`); riding, the problem is left as it is."""
    reference, layout = skate
    t0 = float(reference.times[-1]) - 0.3  # riding on at the target
    window = _window(reference, t0)
    problem = _problem(window)
    coasting = Coasting(layout, RepushBlend(cast(Any, None), layout))
    assert coasting(problem, _inputs(t_ref=t0, manoeuvre=("accelerate", 0.7))) is problem
    speed = layout.speed(layout.prefixes[0])
    assert speed is not None
    ratio = 0.4 / window[0, speed]
    shaped = coasting(problem, _inputs(t_ref=t0, coasting=True, speed=0.4))
    np.testing.assert_allclose(shaped.state_reference[:, speed], ratio * window[:, speed])
    vx = layout.names["vx"]
    np.testing.assert_allclose(shaped.state_reference[:, vx], ratio * window[:, vx])
