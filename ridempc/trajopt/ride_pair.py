"""Pairs of a biped rider and a wheeled board (Cassie on the Hovershoes or the Segway).

Each target speed gives three entries, ``accelerate-<v>``, ``stop-<v>`` and ``turn-<v>``
(:mod:`.ride_problem`), on the board's identified reduced model with the simplified rider
of :mod:`.rider`. Entries are warm-started from the nearest solved entry of the same kind,
resampled onto the new grid.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from functools import cache
from typing import Any

import casadi as ca
import numpy as np

from ridempc.boards import load_board
from ridempc.errors import ConfigError
from ridempc.pair_description import PairDescription, load_pair_description
from ridempc.robots import load_robot
from ridempc.trajopt.pairs import EntrySpec, Guess, Neighbour, Pair
from ridempc.trajopt.platforms import WheeledBoard, wheeled_board
from ridempc.trajopt.problem import TrajectoryProblem
from ridempc.trajopt.ride_problem import (
    KINDS,
    RideOptions,
    build_ride_problem,
    ride_guess,
    ride_rates,
)
from ridempc.trajopt.rider import RiderModel, build_rider

__all__ = ["make_pair", "make_ride_pair", "ride_models"]


@cache
def ride_models(robot_name: str, board_name: str) -> tuple[RiderModel, WheeledBoard]:
    """The simplified rider at its riding keyframe for the board, its hips and leg range
    from the pair file, and the board (built once)."""
    trajopt = load_pair_description(robot_name, board_name).trajopt
    robot = load_robot(robot_name)
    board = load_board(board_name)
    if board is None:
        raise ConfigError(f"board '{board_name}' is missing")
    keyframe = robot.params.stance_keyframes.get(board_name, robot.params.stand_keyframe)
    rider = build_rider(robot, keyframe, trajopt.hips, trajopt.leg_range)
    return rider, wheeled_board(board)


def ride_options(
    overrides: Mapping[str, Any], defaults: Mapping[str, Any] | None = None
) -> RideOptions:
    """:class:`RideOptions` with the pair's ``defaults``, then ``overrides``; an unknown
    field is a ConfigError."""
    merged = {**(defaults or {}), **overrides}
    fields = {f.name for f in dataclasses.fields(RideOptions)}
    unknown = sorted(set(merged) - fields)
    if unknown:
        raise ConfigError(
            f"unknown ride option '{unknown[0]}' (valid: {', '.join(sorted(fields))})"
        )
    return dataclasses.replace(RideOptions(), **merged)


def make_ride_pair(
    robot: str,
    board: str,
    default_targets: tuple[float, ...],
    options: Mapping[str, Any] | None = None,
) -> Pair:
    """The :class:`Pair` of a biped ``robot`` on a wheeled ``board``; ``options`` are the
    pair's own :class:`RideOptions` defaults (an entry's options override them)."""
    defaults = dict(options or {})

    def entries(targets: Sequence[float]) -> list[EntrySpec]:
        return [EntrySpec(kind, float(t)) for t in targets for kind in KINDS]

    def check(spec: EntrySpec) -> None:
        _, wheeled = ride_models(robot, board)
        if spec.kind not in KINDS:
            raise ConfigError(
                f"{robot}-{board} has no '{spec.kind}' trajectories (valid: {', '.join(KINDS)})"
            )
        if not 0.0 < spec.target <= wheeled.speed_limit:
            raise ConfigError(
                f"target {spec.target:g} m/s is unreachable for {robot} on the {board}: its "
                f"speed limit is {wheeled.speed_limit:g} m/s; targets must be in (0, that]"
            )
        ride_options(spec.options, defaults)

    def build(spec: EntrySpec) -> TrajectoryProblem:
        check(spec)
        rider, wheeled = ride_models(robot, board)
        return build_ride_problem(
            rider, wheeled, spec.kind, spec.target, ride_options(spec.options, defaults), spec.name
        )

    def guess(problem: TrajectoryProblem, neighbour: Neighbour | None) -> Guess:
        rider, wheeled = ride_models(robot, board)
        states, inputs = ride_guess(rider, wheeled, problem)
        if neighbour is not None and neighbour.metadata.get("kind") == problem.metadata["kind"]:
            # Same kind: the neighbour's shape in normalised time, on this problem's ramps
            # for the board's speeds and headings (which set the positions).
            s_new = problem.times / problem.times[-1]
            s_old = neighbour.times / neighbour.times[-1]
            keep = [
                i for i in range(12) if problem.state_names[i] not in ("com_x", "com_y", "vx", "vy")
            ]
            for i in keep:
                states[:, i] = np.interp(s_new, s_old, neighbour.states[:, i])
            states[0] = problem.lbw[: problem.nx] * problem.state_scale
            for j in range(problem.nu):
                inputs[:, j] = np.interp(s_new[:-1], s_old[:-1], neighbour.inputs[:, j])
        return Guess(states, inputs, None)

    def rates(metadata: dict[str, Any]) -> ca.Function:
        rider, wheeled = ride_models(robot, board)
        return ride_rates(rider, wheeled)

    def board_states() -> tuple[int, ...]:
        _, wheeled = ride_models(robot, board)
        return tuple(range(12, 12 + len(wheeled.state_names)))

    return Pair(
        robot=robot,
        board=board,
        default_targets=default_targets,
        entries=entries,
        check=check,
        build=build,
        guess=guess,
        rates=rates,
        board_states=board_states,
    )


def make_pair(description: PairDescription) -> Pair:
    """The :class:`Pair` a ``ride`` pair file describes (its targets and option defaults)."""
    return make_ride_pair(
        description.robot,
        description.board,
        description.trajopt.default_targets,
        description.trajopt.problem_options(),
    )
