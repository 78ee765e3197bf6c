"""A quadruped on the skateboard: acceleration trajectories to target speeds (skateboard paper).

Each target speed gives an entry ``accelerate-<v>``: from rest in the riding keyframe to
the board at :math:`v` with all four feet back on the deck (:mod:`.skate_problem`). A
``repush-<v>`` entry (:func:`repush_entry`) starts instead from a board rolling at
:math:`v -` :data:`REPUSH_GAIN` and pushes it back to :math:`v`; the MPC rider takes it
only where a ride holds its speed (a scenario's ``push_off.hold``), blended in from her
state at the switch (:mod:`ridempc.mpc.switch_blend`). Entries are warm-started from the
nearest solved one of their kind by mapping its phases onto the new schedule.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from functools import cache, lru_cache
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ridempc.boards import load_board
from ridempc.errors import ConfigError
from ridempc.pair_description import PairDescription
from ridempc.robots import load_robot
from ridempc.trajopt.pairs import EntrySpec, Guess, Neighbour, Pair
from ridempc.trajopt.problem import TrajectoryProblem
from ridempc.trajopt.rigid_body import RigidBodyRobot, build_rigid_body_robot
from ridempc.trajopt.skate_problem import (
    SkateOptions,
    build_skate_problem,
    skate_guess,
    skate_rates,
    speed_bound,
)
from ridempc.trajopt.skateboard import BOARD_STATE, SkateboardModel, skateboard_model

__all__ = ["REPUSH_GAIN", "make_pair", "repush_entry", "skate_models", "skate_options"]

Array = NDArray[np.float64]
# [m/s] the speed a re-push regains: what the board loses coasting for 1.25 s (0.16 m/s^2 of
# rolling resistance), within one stride's 0.3 m/s (speed_per_stride)
REPUSH_GAIN: float = 0.2


@cache
def skate_models(robot_name: str, board_name: str) -> tuple[RigidBodyRobot, SkateboardModel]:
    """The SRBKM robot at its stance on the board, and the skateboard (built once)."""
    robot = load_robot(robot_name)
    keyframe = robot.params.stance_keyframes.get(board_name, robot.params.stand_keyframe)
    board = load_board(board_name)
    if board is None:
        raise ConfigError(f"board '{board_name}' is missing")
    return build_rigid_body_robot(robot, keyframe), skateboard_model(board)


@lru_cache(maxsize=8)
def _speed_bound(robot_name: str, board_name: str, options: SkateOptions) -> float:
    return speed_bound(skate_models(robot_name, board_name)[0], options)


def skate_options(
    overrides: Mapping[str, Any], defaults: Mapping[str, Any] | None = None
) -> SkateOptions:
    """:class:`SkateOptions` with the pair's ``defaults``, then ``overrides``; an unknown
    field is a ConfigError."""
    merged = {**(defaults or {}), **overrides}
    fields = {f.name for f in dataclasses.fields(SkateOptions)}
    unknown = sorted(set(merged) - fields)
    if unknown:
        raise ConfigError(
            f"unknown skateboard option '{unknown[0]}' (valid: {', '.join(sorted(fields))})"
        )
    return dataclasses.replace(SkateOptions(), **merged)


def _entries(targets: Sequence[float]) -> list[EntrySpec]:
    """Per target an ``accelerate`` from rest and, where its rolling start is no slower
    than the least target (0.3 m/s in the committed library), a ``repush``."""
    least = min(targets, default=0.0)
    repush = [repush_entry(t) for t in targets if t - REPUSH_GAIN >= least - 1e-9]
    return [EntrySpec("accelerate", float(t)) for t in targets] + repush


def repush_entry(target: float) -> EntrySpec:
    """The ``repush`` entry to ``target`` [m/s], from a board rolling :data:`REPUSH_GAIN`
    slower (build it with :func:`ridempc.library.build.solve_entry`)."""
    return EntrySpec("repush", float(target), {"start_speed": round(target - REPUSH_GAIN, 6)})


def _phase_map(new: list[str], old: list[str]) -> list[int]:
    """For each phase of the new schedule, the phase of the old one it resembles: the same
    index from the start, or from the end for the closing phases, or the old schedule's last
    phase of the same mode for the extra strides of a longer schedule."""
    mapping = []
    for j, mode in enumerate(new):
        from_end = len(new) - j
        if j < len(old) - 2 and old[j] == mode:
            mapping.append(j)
        elif from_end <= 2 and old[len(old) - from_end] == mode:
            mapping.append(len(old) - from_end)
        else:
            same = [i for i, m in enumerate(old[:-2]) if m == mode]
            mapping.append(same[-1] if same else min(j, len(old) - 1))
    return mapping


def _warm(problem: TrajectoryProblem, neighbour: Neighbour) -> Guess:
    """Map the neighbour's phases onto this problem's schedule, phase by phase in normalised
    time, then re-integrate the horizontal positions from the mapped velocities."""
    new = problem.metadata["phases"]
    old = neighbour.metadata["phases"]
    mapping = _phase_map([p["mode"] for p in new], [p["mode"] for p in old])
    old_starts = np.concatenate([[0.0], np.cumsum([p["duration"] for p in old])])
    dt = problem.dt
    sources = []
    for j, p in enumerate(new):
        steps = round(p["duration"] / dt)
        i = mapping[j]
        fractions = np.arange(steps) / steps
        sources.append(old_starts[i] + fractions * old[i]["duration"])
    source = np.concatenate([*sources, [neighbour.times[-1]]])

    def sample(values: Array, times: Array) -> Array:
        return np.column_stack(
            [np.interp(source, times, values[:, c]) for c in range(values.shape[1])]
        )

    states = sample(neighbour.states, neighbour.times)
    inputs = sample(neighbour.inputs, neighbour.times[:-1])[:-1]
    nr = problem.nx - len(BOARD_STATE)
    relative = states[:, 0:2] - states[:, nr : nr + 2]
    heading, speed = states[:, nr + 2], states[:, nr + 3]
    velocity = np.column_stack([speed * np.cos(heading), speed * np.sin(heading)])
    board_xy = np.vstack([[0.0, 0.0], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]) * dt, 0)])
    states[:, nr : nr + 2] = board_xy
    states[:, 0:2] = board_xy + relative
    low = problem.lbw[: problem.nx] * problem.state_scale
    fixed = low == problem.ubw[: problem.nx] * problem.state_scale
    states[0, fixed] = low[fixed]  # node 0's fixed part: the keyframe at rest, or a rolling
    # start's board and velocities (its pose is free)
    # Inputs of phases where a foot is now swinging are clipped to zero by the bounds.
    return Guess(states, inputs, None)


def make_pair(description: PairDescription) -> Pair:
    """The :class:`Pair` a ``skate`` pair file describes (its targets and option defaults)."""
    robot_name, board_name = description.robot, description.board
    defaults = dict(description.trajopt.problem_options())

    def check(spec: EntrySpec) -> None:
        if spec.kind not in ("accelerate", "repush"):
            raise ConfigError(
                f"{robot_name}-{board_name} has no '{spec.kind}' trajectories "
                "(valid: accelerate, repush)"
            )
        options = skate_options(spec.options, defaults)
        bound = _speed_bound(robot_name, board_name, options)
        if not 0.0 < spec.target <= bound:
            raise ConfigError(
                f"target {spec.target:g} m/s is unreachable for {robot_name} on the "
                f"{board_name}: no push can help beyond {bound:.1f} m/s (the pushing foot, "
                f"still on the ground for at least {options.min_push:g} s, would have to "
                "sweep farther or faster than its leg allows); targets must be in (0, that]"
            )
        if (spec.kind == "repush") != (options.start_speed > 0.0) or (
            options.start_speed >= spec.target
        ):
            raise ConfigError(
                f"{spec.name}: start_speed {options.start_speed:g} m/s; allowed: 0 for "
                "accelerate, between 0 and the target for repush"
            )

    def build(spec: EntrySpec) -> TrajectoryProblem:
        check(spec)
        robot, board = skate_models(robot_name, board_name)
        options = skate_options(spec.options, defaults)
        return build_skate_problem(robot, board, spec.target, options, spec.name)

    def guess(problem: TrajectoryProblem, neighbour: Neighbour | None) -> Guess:
        robot, board = skate_models(robot_name, board_name)
        if neighbour is not None and neighbour.metadata.get("pair") == problem.metadata["pair"]:
            return _warm(problem, neighbour)
        states, inputs = skate_guess(robot, board, problem)
        return Guess(states, inputs, None)

    def rates(metadata: dict[str, Any]) -> ca.Function:
        robot, board = skate_models(robot_name, board_name)
        return skate_rates(robot, board)

    def board_states() -> tuple[int, ...]:
        robot, _ = skate_models(robot_name, board_name)
        nr = 12 + robot.n_joints
        return tuple(range(nr, nr + len(BOARD_STATE)))

    return Pair(
        robot=robot_name,
        board=board_name,
        default_targets=description.trajopt.default_targets,
        entries=_entries,
        check=check,
        build=build,
        guess=guess,
        rates=rates,
        board_states=board_states,
    )
