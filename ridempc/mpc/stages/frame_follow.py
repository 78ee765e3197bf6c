"""The command source's last step: the commanded roll and turn, and the state in the library
frame moved onto the board (:class:`CommandedFrame`).

At each MPC tick the commands are read over the horizon
(:class:`~ridempc.mpc.stages.commands.CommandHorizon`; on the skateboard the deck's roll
held to what the stance holds, :class:`~ridempc.mpc.stages.deck_roll.StanceRoll`). The
commanded yaw rate :math:`\\omega^*` is integrated into the turn so far,
:math:`\\psi^* = \\int \\omega^* dt` (:class:`~ridempc.mpc.stages.turn.TurnSoFar`), and the
library frame (:class:`~ridempc.mpc.state_map.StateMap`) follows the board onto the
reference's line turned by :math:`\\psi^*`: across it always, along it by what lies beyond
:data:`~ridempc.mpc.state_map.ALONG_SLACK`, and all along it while turning or coasting
(the reference's steady ride is not where a coasting board goes). On a board whose yaw rate
the rider cannot drive (the Segway's, turned by the lean, :mod:`~ridempc.mpc.lean`) the
frame's heading follows the board, carried by the lean's turn rate. On the Hovershoes the
frame follows platform 0 onto its commanded spread line (:mod:`~ridempc.mpc.foot_spread`).
The estimate's headings are then unwrapped to the turned reference's.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import numpy as np
from numpy.typing import NDArray

from ridempc.estimation import EstimatedState
from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.foot_spread import spread_lines
from ridempc.mpc.lean import LeanSteering
from ridempc.mpc.manoeuvre import StateLayout
from ridempc.mpc.stages.base import MpcTick
from ridempc.mpc.stages.commands import CommandHorizon
from ridempc.mpc.stages.deck_roll import StanceRoll
from ridempc.mpc.stages.turn import TurnSoFar
from ridempc.mpc.state_map import StateMap
from ridempc.scenarios.scenario import Command

__all__ = ["CommandedFrame"]

Array = NDArray[np.float64]


class CommandedFrame:
    """The commanded roll and turn over the horizon and the mapped state they start from.

    Args:
        commands: The commands over the horizon.
        mpc: The MPC (its reference, as the manoeuvre in force has it).
        layout: Where the MPC's states are.
        state_map: The library frame, moved onto the board here.
        turn: The commanded turn so far.
        lean: The lean's steering loop (None: the rider turns the board itself).
        stance_roll: The deck's roll held to the stance (None: no deck roll).
        spread_columns: Each platform's columns, where the frame follows platform 0 onto
            its spread line (None: no spread lines).
        follows_heading: Whether the frame's heading follows the board's (a yaw rate the
            rider cannot drive).
    """

    def __init__(
        self,
        commands: CommandHorizon,
        mpc: LinearMpc,
        layout: StateLayout,
        state_map: StateMap,
        turn: TurnSoFar,
        lean: LeanSteering | None,
        stance_roll: StanceRoll | None,
        spread_columns: Sequence[Sequence[int]] | None,
        follows_heading: bool,
    ) -> None:
        self.commands = commands
        self.mpc = mpc
        self.layout = layout
        self.map = state_map
        self.turn = turn
        self.lean = lean
        self.stance_roll = stance_roll
        self.spread_columns = spread_columns
        self.follows_heading = follows_heading

    def __call__(
        self,
        tick: MpcTick,
        command: Command,
        mapped: EstimatedState,
        t_ref: float,
        coasting: bool,
        steering: bool,
    ) -> tuple[Array, Array, Array]:
        """The commanded roll at the horizon's nodes [rad], the turn over its steps
        [rad/s] and the state ``mapped`` (the estimate as the MPC sees it) in the library
        frame moved onto the board at the reference's time ``t_ref`` [s]; ``steering``:
        whether the deck's roll may steer (the rider balancing, or re-pushing off the
        ground)."""
        now, speed = tick.now, tick.speed
        limit = partial(self.stance_roll, tick=tick) if self.stance_roll is not None else None
        names = self.layout.names
        roll, turn = self.commands.roll_and_turn(command, now, speed, steering, limit, names)
        here = self.mpc.reference.states_at(np.array([t_ref]))[0]  # the reference at t_ref
        if self.spread_columns is not None:  # the frame follows platform 0 onto its line
            here = spread_lines(here[None, :], self.spread_columns, command.lateral_offset)[0]
        if self.lean is not None:
            self.lean.update(now, command.yaw_rate, tick.estimate.yaw_rate, speed)
        carried = self.lean.turn_rate if self.lean is not None else 0.0
        self._follow_board(mapped, here, turn, now, coasting, carried)
        x0 = self.turn.unwrapped(self.map.state(mapped), here, self.layout.headings)
        return roll, turn, x0

    def _follow_board(
        self,
        estimate: EstimatedState,
        reference: Array,
        turn: Array,
        now: float,
        coasting: bool,
        yaw_rate: float,
    ) -> None:
        """Integrate the commanded turn and move the library frame onto the board (the
        ``reference`` state of this tick), its heading carried by ``yaw_rate`` [rad/s]
        where it follows the board's."""
        turned = self.turn.advance(now, float(turn[0]))
        x, y, heading = self.layout.board_pose(reference)
        along = coasting or bool(np.any(turn)) or turned != 0.0
        self.map.follow_sideways(
            estimate,
            (x, y, heading + turned),
            along=along,
            heading=self.follows_heading,
            yaw_rate=yaw_rate,
        )
        self.map.follow_ground(estimate)
