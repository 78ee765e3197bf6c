"""Scenarios: command timelines, disturbances, noise and parameter changes, validated on load."""

from ridempc.scenarios.library import (
    library_files,
    resolve_scenario,
    scenario_applies,
    scenario_names,
)
from ridempc.scenarios.scenario import (
    Command,
    CommandEvent,
    CommandWave,
    Disturbance,
    ParameterChange,
    Scenario,
    load_scenario_file,
)

__all__ = [
    "Command",
    "CommandEvent",
    "CommandWave",
    "Disturbance",
    "ParameterChange",
    "Scenario",
    "load_scenario_file",
    "library_files",
    "resolve_scenario",
    "scenario_applies",
    "scenario_names",
]
