"""Which library trajectory the MPC tracks for the command, and the command laid over it.

The motion library holds manoeuvres from rest or between steady speeds (``accelerate``,
``stop``, ``turn``); a ride is a sequence of them:

- **hold**: before any speed is commanded, the first ``accelerate`` entry's initial state
  (standing on the board at rest) is held: the reference time stays before its start;
- **accelerate** to the commanded speed :math:`v^*` [m/s] (the nearest entry, or a blend of
  the two neighbouring ones where the library allows it), started *at the phase where the
  reference's speed equals the rider's estimated speed* (its centre of mass's, along the
  board's heading, as the reference's ``vx`` is), so a step from 0.5 to 1.0 m/s picks
  up the 1.0 m/s push where it passes 0.5 m/s, and one from rest where it passes the pair's
  start speed (:attr:`~ridempc.mpc.pairs.MpcPair.start_speed`); after its end the
  reference rides on steadily
  (where the library has no ``stop``, the skateboard, which only a push drives, it
  **coasts**: the steady ride slowed to the board's speed, :meth:`ManoeuvreSelector.coasting`);
  while the command is ramping, it is kept as long as the command stays within
  ``RETARGET_BAND`` of its target (a ramp retargets in a few steps, not at every tick), and
  it moves to the exact command once the command settles; a lower speed that is not rest
  starts at the entry's end, riding steadily at it;
- **repush** where the library has ``repush`` entries (the skateboard's): a coasting rider
  whose board has slowed :data:`REPUSH_BAND` below the commanded speed pushes one more
  stride from the rolling board back up to it (:meth:`ManoeuvreSelector.repush`), and
  coasts again at its end;
- **stop** when the command returns to zero, where the library has ``stop`` entries (the
  skateboard has none: it coasts on, four-leg balancing); also to **ride out a push** that
  leaves a rider holding still more than ``RETARGET_BAND`` faster than rest (the stop from
  her speed: the board carries her on and brakes as the library found feasible, as the PD
  lets it, where rest held at once fought the push); and to **slow down** while the
  rider is more than ``RETARGET_BAND`` faster than a commanded speed that is not rest: the
  stop from the rider's speed, started at its phase, brakes as the library found feasible,
  and once the rider is down to the command the ``accelerate`` entry of that speed rides
  on at it (started at its end). A speed reference stepped down instead (0.25 m/s at a
  time, as a ramp retargets) braked the Segway from 4 m/s into a fall.

Targets beyond the library's range are clamped to it. On top of the trajectory the command
sets the deck roll (the skateboard's ``board_roll`` and ``board_roll_rate``) over the
horizon when it commands one: the command's own timeline where the ride's commands are
planned ahead (the rider's ``command_preview``), else the present command extrapolated at
its rate, and moves the rider's pose, sway and
forces to the balance of that roll (:mod:`ridempc.mpc.statics`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ridempc.boards.canonical import BoardState, board_state_columns
from ridempc.errors import ConfigError
from ridempc.library.store import library_folder
from ridempc.mpc.problem import MpcProblem
from ridempc.mpc.statics import StaticShift
from ridempc.scenarios.scenario import Command

if TYPE_CHECKING:  # the pairs build their settings from this module's neighbours
    from ridempc.mpc.pairs import MpcPair

__all__ = [
    "HOLD",
    "MOVING",
    "REPUSH",
    "REPUSH_BAND",
    "RETARGET_BAND",
    "Manoeuvre",
    "ManoeuvreSelector",
    "StateLayout",
    "turn_headings",
]

Array = NDArray[np.float64]
MOVING: float = 0.05  # [m/s] a commanded speed below this is rest
HOLD: str = "hold"
REPUSH: str = "repush"  # a stride pushed again from a rolling board (the skateboard's)
# [m/s] how far below the commanded speed a coasting board is pushed again: the speed a
# ``repush`` entry regains (ridempc.trajopt.skate_pair.REPUSH_GAIN)
REPUSH_BAND: float = 0.2
# [m/s] a running ``accelerate`` is kept while the command stays this close to its target: a
# ramped command would otherwise restart the trajectory at every MPC tick (the Segway's
# 0 -> 1 m/s ramp over 1 s retargeted 30 times, its reference time jumping between 0 and
# 1.3 s, and fell).
RETARGET_BAND: float = 0.25


def turn_headings(states: Array, layout: StateLayout, turned: Array, rates: Array) -> None:
    """Turn a reference's headings and yaw rates in place, node by node: every heading (the
    base's yaw, the platforms' canonical ``heading``) gains ``turned`` [rad] and every yaw
    rate (the base's :math:`\\omega_z`, the platforms' ``yaw_rate``) gains ``rates``
    [rad/s], both (nodes,)."""
    for index in layout.headings:
        states[:, index] += turned
    for index in layout.yaw_rates:
        states[:, index] += rates


@dataclass(frozen=True)
class Manoeuvre:
    """A library trajectory and when it started.

    Attributes:
        kind: ``hold``, ``accelerate``, ``repush`` or ``stop``.
        target: The entry's target speed [m/s].
        start: Simulation time at which the reference's time is zero [s].
        gain: For a ``repush``, the speed it is asked to add beyond its entry's [m/s]
            (:mod:`~ridempc.mpc.push_speed`).
    """

    kind: str
    target: float
    start: float = 0.0
    gain: float = 0.0

    @property
    def library_kind(self) -> str:
        return "accelerate" if self.kind == HOLD else self.kind

    def started(self, now: float) -> Manoeuvre:
        return self if self.kind != HOLD else replace(self, start=now)

    def reference_time(self, now: float) -> float:
        """The reference's time [s]; a hold stays before the trajectory's start."""
        return -1.0 if self.kind == HOLD else now - self.start


@dataclass(frozen=True)
class StateLayout:
    """Where the board and the base sit in a pair's state names.

    Attributes:
        prefixes: Each platform's state prefix, in platform order (``board_``, ``left_`` and
            ``right_``, ``segway_``), as the board declares them.
        base_prefix: The base's angle prefix (``trunk_``, ``pelvis_``): its base body's.
        names: Index of each state name.
        board: Index of each board state, by its platform and canonical quantity
            (:mod:`ridempc.boards.canonical`).
    """

    prefixes: tuple[str, ...]
    base_prefix: str
    names: dict[str, int]
    board: Mapping[BoardState, int]

    @classmethod
    def from_pair(cls, state_names: Sequence[str], pair: MpcPair) -> StateLayout:
        """The layout a pair declares: its platforms' prefixes (``MpcPair.platform_prefixes``),
        its board states' quantities (``MpcPair.board_states``) and its robot's base body
        (``MpcPair.base``, whose angles are ``<base>_roll`` ...).

        Raises ConfigError: the names have no ``<base>_roll`` or no platform's ``x``."""
        names = list(state_names)
        board = board_state_columns(names, pair.board_states)
        prefixes, base = tuple(pair.platform_prefixes), pair.base
        missing = [n for n in (f"{base}_roll", f"{base}_yaw", "wz") if n not in names] + [
            f"{p}x" for k, p in enumerate(prefixes) if BoardState(k, "x") not in board
        ]
        if missing:
            raise ConfigError(f"no state '{missing[0]}' among the states {names}")
        return cls(prefixes, f"{base}_", {n: i for i, n in enumerate(names)}, board)

    def column(self, prefix: str, quantity: str) -> int | None:
        """The index of a platform's state of a canonical ``quantity``, or None."""
        return self.board.get(BoardState(self.prefixes.index(prefix), quantity))

    @property
    def headings(self) -> tuple[int, ...]:
        """Indices of the headings: the base's yaw and each platform's ``heading``."""
        platforms = (self.column(p, "heading") for p in self.prefixes)
        return (self.names[f"{self.base_prefix}yaw"], *(i for i in platforms if i is not None))

    @property
    def yaw_rates(self) -> tuple[int, ...]:
        """Indices of the yaw rates: the base's :math:`\\omega_z` and each platform's."""
        platforms = (self.column(p, "yaw_rate") for p in self.prefixes)
        return (self.names["wz"], *(i for i in platforms if i is not None))

    @property
    def rider_states(self) -> tuple[int, ...]:
        """Indices of the states that are not a platform's (the rider's)."""
        return tuple(i for n, i in self.names.items() if not n.startswith(self.prefixes))

    def heading(self, prefix: str) -> int | None:
        """The index of a platform's heading state (canonical ``heading``)."""
        return self.column(prefix, "heading")

    def speed(self, prefix: str) -> int | None:
        """The index of a platform's speed state (canonical ``speed``)."""
        return self.column(prefix, "speed")

    def position(self, prefix: str) -> list[int]:
        """The indices of a platform's origin, its canonical ``x`` and ``y``."""
        return [self.board[BoardState(self.prefixes.index(prefix), axis)] for axis in "xy"]

    def board_pose(self, state: Array) -> tuple[float, float, float]:
        """The first platform's (x, y, heading) in a state."""
        prefix = self.prefixes[0]
        heading = self.heading(prefix)
        if heading is None:
            raise ConfigError(f"no heading state for platform '{prefix}'")
        x, y = state[self.position(prefix)]
        return float(x), float(y), float(state[heading])


class ManoeuvreSelector:
    """Picks the manoeuvre for a command (see the module docstring).

    Args:
        robot: Robot name.
        board: Board name.

    Raises:
        ConfigError: The pair's library is missing or has no ``accelerate`` entries.
    """

    def __init__(self, robot: str, board: str) -> None:
        from ridempc.library.store import read_manifest

        folder = library_folder(robot, board)
        manifest = read_manifest(folder)
        self.targets: dict[str, tuple[float, ...]] = {}
        for entry in manifest.entries:
            self.targets.setdefault(entry.kind, ())
            self.targets[entry.kind] = tuple(sorted({*self.targets[entry.kind], entry.target}))
        if "accelerate" not in self.targets:
            raise ConfigError(f"{folder / 'manifest.json'}: no 'accelerate' entries")
        self._last_wanted: float | None = None  # the commanded speed at the last call
        # pushed again while rolling only where the ride asks to hold its speed: a push-off
        # coasts after its push, as the paper's does (and as its measured figures were)
        self.holds_speed = False

    def initial(self) -> Manoeuvre:
        return Manoeuvre(HOLD, self.targets["accelerate"][0])

    def _clamped(self, kind: str, target: float) -> float:
        targets = self.targets[kind]
        return float(min(max(target, targets[0]), targets[-1]))

    def select(self, command: Command, current: Manoeuvre, now: float, speed: float) -> Manoeuvre:
        """The manoeuvre for ``command`` at ``now`` [s], the rider at ``speed`` [m/s].

        A new manoeuvre's ``start`` is provisional (``now``); the rider moves it to match
        the reference's speed phase (:meth:`phase_start`).
        """
        wanted = command.velocity
        if wanted < MOVING:
            if current.kind == HOLD and "stop" in self.targets and speed > RETARGET_BAND:
                return Manoeuvre("stop", self._clamped("stop", speed), now)  # pushed: ride out
            if current.kind in (HOLD, "stop") or "stop" not in self.targets:
                return current
            return Manoeuvre("stop", self._clamped("stop", max(speed, current.target)), now)
        previous, self._last_wanted = self._last_wanted, wanted
        if "stop" in self.targets and speed > wanted + RETARGET_BAND:
            if current.kind == "stop":
                return current
            return Manoeuvre("stop", self._clamped("stop", speed), now)
        goal = Manoeuvre("accelerate", self._clamped("accelerate", wanted), now)
        if current.kind == REPUSH and abs(current.target - self._clamped(REPUSH, wanted)) < 1e-6:
            return current
        if current.kind == "accelerate":
            gap = abs(goal.target - current.target)
            ramping = previous is not None and not math.isclose(previous, wanted, abs_tol=1e-9)
            if gap < 1e-6 or (ramping and gap < RETARGET_BAND):
                return current
        return goal

    def repush(
        self, command: Command, current: Manoeuvre, now: float, speed: float, gain: float = 0.0
    ) -> Manoeuvre:
        """A stride pushed again from the rolling board, or ``current``: on a board the
        rider drives only by pushing (no ``stop`` entries), once the board has slowed
        :data:`REPUSH_BAND` less ``gain`` below a commanded speed that is not rest, the
        library's ``repush`` entry of that speed (clamped to its range), which starts from a
        board rolling :data:`REPUSH_BAND` slower, asked for ``gain`` more. Only where the
        ride holds its speed (:attr:`holds_speed`, a scenario's ``push_off.hold``); the
        caller asks only while the rider coasts.

        Args:
            command: The command of the moment.
            current: The manoeuvre under way (coasting at its end).
            now: Time [s].
            speed: The board's speed [m/s].
            gain: The held speed's outer loop's :math:`u` [m/s] (:mod:`~ridempc.mpc.push_speed`).
        """
        wanted = command.velocity
        if not self.holds_speed or REPUSH not in self.targets:
            return current
        if wanted < MOVING or speed > wanted - REPUSH_BAND + gain:
            return current
        return Manoeuvre(REPUSH, self._clamped(REPUSH, wanted), now, gain)

    @staticmethod
    def phase_start(
        times: Array, speeds: Array, speed: float, now: float, kind: str, least: float = 0.0
    ) -> float:
        """The start time that puts ``now`` at the reference's first time where its speed
        reaches ``speed`` (rising for ``accelerate``, falling for ``stop``).

        An ``accelerate`` matches at least ``least`` [m/s]: started from rest, it skips the
        reference's steady start and whatever of the lean-in is slower than that
        (:attr:`~ridempc.mpc.pairs.MpcPair.start_speed`).

        A ``repush`` starts at its start: the rider pushes again when the board has slowed
        to the entry's rolling start.

        A rider already faster than the whole ``accelerate`` reference (a slow-down to a
        lower speed that is not rest) starts at the reference's end, riding steadily at
        its target: the MPC brakes to it. Started from rest instead, the reference asked a
        rider at 4 m/s for 0 m/s at once (the Segway's stop from 4 m/s fell in 0.3 s).
        """
        if kind == REPUSH:  # from its rolling start, the speed the board was pushed at:
            return now  # matched later, the rider at 0.52 m/s joined a 0.5 one mid-push
        if kind == "accelerate":
            speed = max(speed, least)
            reached = np.nonzero(speeds >= speed)[0]
            beyond = speed > float(speeds[-1])
        else:
            reached = np.nonzero(speeds <= speed)[0]
            beyond = False
        if beyond:
            t_match = float(times[-1])
        else:
            t_match = float(times[reached[0]]) if reached.size else 0.0
        return now - t_match

    @property
    def coasts(self) -> bool:
        """Whether the rider coasts after an ``accelerate``: a pair without ``stop`` entries
        (the skateboard), whose board the rider drives only by pushing off the ground."""
        return "stop" not in self.targets

    @staticmethod
    def coasting(problem: MpcProblem, layout: StateLayout, speed: float) -> MpcProblem:
        """The steady ride after an ``accelerate``'s end slowed to the board's ``speed``
        [m/s]: a board that nothing pushes coasts (on the skateboard, rolling resistance
        takes 0.16 m/s off every second), and a reference riding on at the target asked
        the rider to drive a deck it stands on.

        With :math:`r = \\max(v, 0) / v_{ref}` (:math:`v_{ref}` the reference's board speed
        at node 0; :math:`r = 0` at rest), the horizontal speeds of the centre of mass and
        of every platform are scaled by :math:`r` and the horizontal positions' steps from
        node 0 too: :math:`p_k = p_0 + r (p^{ref}_k - p_0)`. The rider's pose, the forces
        and the deck's roll are the reference's.
        """
        names = layout.names
        states = problem.state_reference.copy()
        speeds = [layout.speed(p) for p in layout.prefixes]
        if speeds[0] is None:
            raise ConfigError(f"no speed state for platform '{layout.prefixes[0]}'")
        reference = float(states[0, speeds[0]])
        ratio = max(speed, 0.0) / reference if reference > MOVING else 0.0
        platforms = [i for p in layout.prefixes for i in layout.position(p)]
        for i in (names["com_x"], names["com_y"], *platforms):
            states[:, i] = states[0, i] + ratio * (states[:, i] - states[0, i])
        for i in (names["vx"], names["vy"], *(i for i in speeds if i is not None)):
            states[:, i] *= ratio
        return replace(problem, state_reference=states)

    @staticmethod
    def with_turn(
        problem: MpcProblem, layout: StateLayout, rates: Array, turned: float = 0.0
    ) -> MpcProblem:
        """The problem's reference turned at the commanded yaw rates :math:`\\omega^*_k`
        [rad/s] over the horizon's steps (unchanged when all are zero and nothing is
        turned yet), the rider and her platforms turning as one body.

        With :math:`\\Delta\\psi_k = \\psi_0 + \\sum_{j<k} \\omega^*_j \\Delta t` the heading
        turned by node :math:`k` (``turned`` [rad], :math:`\\psi_0`, is the turn commanded
        so far, which the rider integrates: the heading is tracked, and a turn once made
        is kept when the command ends), every heading (the platforms' and the base's yaw)
        gains :math:`\\Delta\\psi_k` and every yaw rate (the platforms' and the base's
        :math:`\\omega_z`, level base) gains :math:`\\omega^*_k`. The centre of mass rides
        the arc: its velocity and the steps of its path are turned by
        :math:`R_k = R_z(\\Delta\\psi_k)`, from its node-0 place turned by :math:`\\psi_0`
        about platform 0's (where the library frame puts the board). Each platform keeps
        its place in the rider's frame, :math:`p_{i,k} = c_k + R_k (\\bar p_{i,k} - \\bar c_k)`
        (bars: the reference's), so that two Hovershoes stay side by side as they turn
        (their headings turned while their offsets were not: after half a radian the
        reference put the outer shoe 0.2 m behind its place beside the inner), and its
        speed is its point's on a body turning at :math:`\\omega^*_k`,
        :math:`v_{i,k} = \\bar v_{i,k} - \\omega^*_k\\, l_{i,k}`, with :math:`l_{i,k}` [m]
        its offset to the left of the centre of mass across its heading (the inner shoe
        rolls slower).
        """
        rates = np.asarray(rates, dtype=float)
        if not np.any(rates) and turned == 0.0:
            return problem
        names = layout.names
        states = problem.state_reference.copy()
        ahead = np.cumsum(rates[: states.shape[0] - 1] * problem.dt)
        turned_k = turned + np.concatenate([[0.0], ahead])
        step_rates = np.concatenate([rates[: states.shape[0] - 1], rates[-1:]])[: len(turned_k)]
        cos, sin = np.cos(turned_k), np.sin(turned_k)

        def turn(xy: Array) -> Array:
            """Row :math:`k` turned by :math:`R_k`."""
            c, s = cos[: len(xy)], sin[: len(xy)]
            return np.column_stack([c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]])

        com = [names["com_x"], names["com_y"]]
        pivot = states[0, layout.position(layout.prefixes[0])]
        centre = states[:, com]
        start = pivot + turn(centre[:1] - pivot)[0]
        steps = turn(np.diff(centre, axis=0))
        turned_centre = start + np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])
        for prefix in layout.prefixes:
            columns = layout.position(prefix)
            offset = states[:, columns] - centre
            index = layout.heading(prefix)
            heading = np.zeros(len(states)) if index is None else states[:, index]
            left = np.cos(heading) * offset[:, 1] - np.sin(heading) * offset[:, 0]
            speed = layout.speed(prefix)
            if speed is not None:
                states[:, speed] -= step_rates * left
            states[:, columns] = turned_centre + turn(offset)
        states[:, com] = turned_centre
        velocity = [names["vx"], names["vy"]]
        states[:, velocity] = turn(states[:, velocity])
        turn_headings(states, layout, turned_k, step_rates)
        return replace(problem, state_reference=states)

    @staticmethod
    def commands_roll(names: dict[str, int], roll: Array) -> bool:
        """Whether the commanded deck roll over the horizon, ``roll`` [rad], sets a roll the
        reference has (a pair with a ``board_roll`` state, a roll that is not all zero)."""
        return "board_roll" in names and bool(np.any(np.asarray(roll) != 0.0))

    @classmethod
    def with_command(
        cls,
        problem: MpcProblem,
        names: dict[str, int],
        roll: Array,
        balance: StaticShift | None = None,
    ) -> MpcProblem:
        """The problem with the commanded deck roll laid over the reference (if it has one),
        and with ``balance``, the reference's change per radian of roll and per rad/s of
        roll rate (:meth:`~ridempc.mpc.controller.LinearMpc.static_shift`), moved to stay
        in balance.

        Args:
            problem: The tick's problem.
            names: State indices by name.
            roll: Commanded deck roll at each of the horizon's nodes [rad]; its rate [rad/s]
                is the central difference over the nodes' step.
            balance: The static shift, or None to lay the roll over the reference alone.
        """
        if not cls.commands_roll(names, roll):
            return problem
        states = problem.state_reference.copy()
        inputs = problem.input_reference.copy()
        wanted = np.broadcast_to(np.asarray(roll, dtype=float), (states.shape[0],))
        rate = np.gradient(wanted, problem.dt) if wanted.size > 1 else np.zeros(1)
        index = names["board_roll"]
        if balance is not None:
            change = wanted - states[:, index]
            states += np.outer(change, balance.states) + np.outer(rate, balance.velocities)
            inputs += np.outer(change[:-1], balance.inputs)
        states[:, index] = wanted
        if "board_roll_rate" in names:
            states[:, names["board_roll_rate"]] = rate
        return replace(problem, state_reference=states, input_reference=inputs)
