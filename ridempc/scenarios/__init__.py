"""Scenarios: command timelines, disturbances, noise and parameter changes, validated on load."""

from ridempc.scenarios.library import resolve_scenario, scenario_names
from ridempc.scenarios.scenario import (
    Command,
    CommandEvent,
    Disturbance,
    ParameterChange,
    Scenario,
    load_scenario_file,
)

__all__ = [
    "Command",
    "CommandEvent",
    "Disturbance",
    "ParameterChange",
    "Scenario",
    "load_scenario_file",
    "resolve_scenario",
    "scenario_names",
]
