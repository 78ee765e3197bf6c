"""The command source of the manoeuvre: which library trajectory the command asks for.

At each MPC tick the selector (:class:`~ridempc.mpc.manoeuvre.ManoeuvreSelector`) reads the
command (its speed read ahead where the pair previews it,
:meth:`~ridempc.mpc.stages.commands.CommandHorizon.speed_command`): a push-off or a speed
change follows its library trajectory, then rides on; on a board only a push drives, once
the coast has slowed below the command, it pushes again from the rolling board (the
library's ``repush``), from the side its turn needs (:mod:`~ridempc.mpc.push_side`), when
and with the gain the held speed's outer loop asks (:mod:`~ridempc.mpc.push_speed`). The
manoeuvre is chosen, and its phase matched, on the centre of mass's speed, which the
reference's ``vx`` is: read off the feet, a Segway's speed swung +-0.3 m/s about the
rider's at 3-4 m/s and started a 4 m/s push 0.36 m/s ahead of the rider.
"""

from __future__ import annotations

from dataclasses import replace

from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.manoeuvre import REPUSH, Manoeuvre, ManoeuvreSelector, StateLayout
from ridempc.mpc.pairs import MpcPair
from ridempc.mpc.push_side import PushSide, first_stride
from ridempc.mpc.push_speed import StrokeSpeedLoop
from ridempc.mpc.stages.commands import CommandHorizon
from ridempc.scenarios.scenario import Command

__all__ = ["ManoeuvreChoice"]


class ManoeuvreChoice:
    """The manoeuvre the command asks for, the MPC retargeted to its library entry.

    Args:
        selector: The pair's manoeuvres.
        mpc: The MPC, whose reference a new manoeuvre replaces.
        layout: The pair's state layout.
        pair: The pair (its board states and start speed).
        push_side: Which side each re-push comes from, or None (the library's own).
        commands: The command source.
    """

    def __init__(
        self,
        selector: ManoeuvreSelector,
        mpc: LinearMpc,
        layout: StateLayout,
        pair: MpcPair,
        push_side: PushSide | None,
        commands: CommandHorizon,
    ) -> None:
        self._selector, self._mpc, self._layout = selector, mpc, layout
        self._pair, self._push_side, self._commands = pair, push_side, commands
        self.speed_loop = StrokeSpeedLoop()

    def __call__(
        self,
        manoeuvre: Manoeuvre,
        command: Command,
        now: float,
        speed: float,
        rider_speed: float,
        coasting: bool,
    ) -> Manoeuvre | None:
        """The manoeuvre begun at ``now`` [s], its phase matched to ``rider_speed`` [m/s],
        or None to go on with ``manoeuvre``; ``speed``: the board's [m/s]; ``coasting``:
        whether the rider coasts on ``manoeuvre``."""
        selector, mpc = self._selector, self._mpc
        asked = self._commands.speed_command(command, now)
        wanted = selector.select(asked, manoeuvre, now, rider_speed)
        loop = self.speed_loop  # over the ride held after its push-off: coasts and re-pushes
        if selector.holds_speed and (coasting or manoeuvre.kind == REPUSH):
            loop.observe(now, speed)
        else:
            loop.reset()
        if wanted is manoeuvre and coasting:  # slowed: push again
            wanted = selector.repush(command, wanted, now, speed, loop.gain)
            if wanted is not manoeuvre:  # a stride ends: the loop's sample, its gain asked
                wanted = replace(wanted, gain=loop.stride(now, command.velocity))
        if wanted is manoeuvre:
            return None
        mpc.retarget(wanted.library_kind, wanted.target)
        if wanted.kind == REPUSH and self._push_side is not None:
            window = first_stride(mpc.reference)
            turn = self._commands.yaw_rate_ahead(command, now, window)
            mpc.reference = self._push_side.reference(mpc.reference, turn, self._pair.board_states)
        reference = mpc.reference
        start = selector.phase_start(
            reference.times,
            reference.states[:, self._layout.names["vx"]],
            rider_speed,
            now,
            wanted.kind,
            self._pair.start_speed,
        )
        return replace(wanted, start=start)
