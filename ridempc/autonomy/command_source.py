"""A scenario whose commands come from a source (a planner) instead of its timeline.

The simulation reads a ride's commands, and the controller its command preview, from
``Scenario.command_at``; a :class:`SourcedScenario` answers from its source, so a planner
drives a ride without any change to the run loop.
"""

from __future__ import annotations

from collections.abc import Callable

from pydantic import PrivateAttr

from ridempc.scenarios.scenario import Command, Scenario

__all__ = ["SourcedScenario"]


class SourcedScenario(Scenario):
    """A scenario whose :meth:`command_at` asks ``source`` (set by :meth:`with_source`)."""

    _source: Callable[[float], Command] | None = PrivateAttr(default=None)

    def with_source(self, source: Callable[[float], Command]) -> SourcedScenario:
        sourced = self.model_copy()
        sourced._source = source
        return sourced

    def command_at(self, t: float) -> Command:
        if self._source is None:
            return super().command_at(t)
        return self._source(t)
