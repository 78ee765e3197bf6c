"""Variants of a scenario drawn from a distribution, and each one as a scenario file.

Variant ``i`` of a sweep with seed ``K`` comes from ``numpy.random.default_rng([K, i])``
alone: its ride seed first, then every quantity of the distribution in the order of
:meth:`~ridempc.sweep.distribution.Distribution.quantities`. The same seed therefore gives
the same variants whatever the number of samples (a sweep of 50 is the first 50 of a sweep
of 100), and any variant is drawn again without the others.

A variant is the base scenario with the draws added: pushes and kicks appended to its
disturbances, a payload and the knobs appended to its changes, the start offsets added to
its own, its sensor noise scaled, a drawn slope or step added to its terrain, a drawn turn
added to its commands.
:func:`scenario_toml` writes it as a file that ``ridempc sim --scenario`` reads back to an
equal scenario.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import ValidationError

from ridempc.errors import ConfigError
from ridempc.options import MAX_SEED
from ridempc.scenarios.scenario import Scenario
from ridempc.sweep.distribution import Distribution, DrawnChange, Kick
from ridempc.sweep.steering_draws import own_yaw_commands, turn_events
from ridempc.sweep.terrain_draws import CHOICES as TERRAIN_CHOICES
from ridempc.sweep.tomltext import toml_text

__all__ = ["Variant", "draw_variants", "scenario_toml", "variant_id"]

# The id's digits: v0000 to v9999 sort as numbers; a larger sweep's ids grow a digit.
ID_DIGITS: int = 4
# A payload lighter than a gram is no payload (a fraction drawn at 0): the change is left out.
MIN_PAYLOAD_KG: float = 1e-3


@dataclass(frozen=True)
class Variant:
    """One drawn variant of a scenario.

    Attributes:
        id: ``v0000``, ``v0001``, ... (the zero-padded index).
        index: Its index in the sweep.
        seed: The ride seed (sensor noise), drawn from the variant's own generator.
        scenario: The base scenario with the drawn changes, named ``<base>-<id>``.
        drawn: Every quantity that varies, by its dotted name (e.g. ``push.magnitude``
            [N/kg]), as drawn.
    """

    id: str
    index: int
    seed: int
    scenario: Scenario
    drawn: dict[str, float]


def variant_id(index: int) -> str:
    """The id of variant ``index``: ``v0042``."""
    return f"v{index:0{ID_DIGITS}d}"


def draw_variants(
    scenario: Scenario,
    distribution: Distribution,
    *,
    robot: str,
    board: str,
    samples: int,
    seed: int,
) -> list[Variant]:
    """Draw ``samples`` variants of ``scenario`` for ``robot`` on ``board``.

    Args:
        scenario: The base scenario.
        distribution: What is drawn (:func:`~ridempc.sweep.distribution.load_distribution`).
        robot: The rider (its mass scales pushes' and payloads' fractions), or ``none``.
        board: The board (its independent platforms get start offsets each).
        samples: How many variants, at least 1.
        seed: The sweep's seed, in [0, 2**32 - 1].

    Raises:
        UnknownNameError: An unknown robot or board.
        ConfigError: ``samples`` below 1, a seed out of range, a distribution for another
            board, a push, kick or change that may come after the ride's end, or a variant
            the scenario's checks refuse (e.g. noise scaled beyond a sensor's bound).
    """
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ConfigError(f"--samples {samples!r}: allowed: an integer of at least 1")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise ConfigError(f"--seed {seed!r}: allowed: an integer in [0, {MAX_SEED}]")
    if distribution.board is not None and distribution.board != board:
        raise ConfigError(
            f"distribution '{distribution.name}' is for board '{distribution.board}'; "
            f"allowed: one for board '{board}' or for any board"
        )
    from ridempc.boards import load_board
    from ridempc.boards.steering import check_steering

    rider_mass, platforms = _rider_and_platforms(robot, board)
    _check_times(scenario, distribution)
    laws = distribution.quantities(platforms)
    steered = load_board(board) if distribution.steering is not None else None
    variants = []
    for index in range(samples):
        rng = np.random.default_rng([seed, index])
        ride_seed = int(rng.integers(0, MAX_SEED, endpoint=True))
        values = {name: law.draw(rng) for name, law in laws.items()}
        name = f"{scenario.name}-{variant_id(index)}"
        about = (
            f"variant {variant_id(index)} of '{scenario.name}' drawn from distribution "
            f"'{distribution.name}' (sweep seed {seed})"
        )
        fields = _variant_fields(scenario, distribution, values, rider_mass, platforms)
        fields |= {"name": name, "description": about}
        try:
            variant = Scenario.model_validate(fields)
        except ValidationError as exc:
            where = f"distribution '{distribution.name}', variant {variant_id(index)}"
            raise ConfigError.from_validation(where, exc, Scenario) from exc
        if distribution.steering is not None:  # a turn the board cannot make (the skateboard's)
            check_steering(variant, steered)
        drawn = {k: v for k, v in values.items() if laws[k].random}
        if distribution.terrain is not None:  # what is ridden: 0 where nothing is laid
            drawn = {k: v for k, v in drawn.items() if k not in TERRAIN_CHOICES}
            drawn |= distribution.terrain.drawn(values)
        variants.append(Variant(variant_id(index), index, ride_seed, variant, drawn))
    return variants


def scenario_toml(scenario: Scenario) -> str:
    """A scenario file's text that :func:`~ridempc.scenarios.load_scenario_file` reads back
    to an equal :class:`~ridempc.scenarios.Scenario` (every number written exactly)."""
    return toml_text(scenario.model_dump(mode="python", exclude_none=True))


def _rider_and_platforms(robot: str, board: str) -> tuple[float, int]:
    """The rider's mass [kg] and the board's independent platforms (0 for one)."""
    from ridempc.boards import load_board
    from ridempc.controllers import NO_ROBOT
    from ridempc.robots import load_robot

    loaded = load_board(board)
    platforms = len(loaded.params.platform_sites) if loaded is not None else 0
    if robot != NO_ROBOT:
        return load_robot(robot).mass, platforms if platforms > 1 else 0
    if loaded is None:
        raise ConfigError(f"robot '{NO_ROBOT}' (a dead weight) needs a board to ride")
    mass = load_robot(loaded.params.dead_weight_robot).mass
    return mass, platforms if platforms > 1 else 0


def _check_times(scenario: Scenario, distribution: Distribution) -> None:
    """Every drawn event within the ride, whatever is drawn: a late one is a mistake."""
    events = [(f"pushes.{i}.t", p.t) for i, p in enumerate(distribution.pushes)]
    events += [(f"kicks.{i}.t", k.t) for i, k in enumerate(distribution.kicks)]
    events += [(f"changes.{i}.t", c.t) for i, c in enumerate(distribution.changes)]
    for where, law in events:
        latest = law.bounds()[1]
        if latest > scenario.duration:
            raise ConfigError(
                f"distribution '{distribution.name}': field '{where}': draws up to "
                f"{latest:g} s; allowed: within scenario '{scenario.name}' "
                f"({scenario.duration:g} s)"
            )
    if distribution.steering is not None:
        own = own_yaw_commands(scenario)
        if own is not None:
            raise ConfigError(
                f"distribution '{distribution.name}': field 'steering': scenario "
                f"'{scenario.name}' commands its own yaw rate ({own}); allowed: a base "
                "scenario without yaw-rate commands, waves or a path"
            )
        end = distribution.steering.latest_end()
        if end > scenario.duration:
            raise ConfigError(
                f"distribution '{distribution.name}': field 'steering': the turn ends up to "
                f"{end:g} s (t + duration + ramp); allowed: within scenario "
                f"'{scenario.name}' ({scenario.duration:g} s)"
            )


def horizontal_force(magnitude: float, direction_deg: float) -> tuple[float, float, float]:
    """A force of ``magnitude`` in the horizontal plane, ``direction_deg`` [deg]
    counter-clockwise from the +x (forward) axis: (x, y, 0)."""
    angle = math.radians(direction_deg)
    return (magnitude * math.cos(angle), magnitude * math.sin(angle), 0.0)


def _variant_fields(
    scenario: Scenario,
    distribution: Distribution,
    values: Mapping[str, float],
    rider_mass: float,
    platforms: int,
) -> dict[str, Any]:
    """The base scenario's fields with the drawn values applied (unchecked)."""
    fields = scenario.model_dump(mode="python")
    disturbances = list(fields["disturbances"])
    for kind, events in (("push", distribution.pushes), ("kick", distribution.kicks)):
        for i, event in enumerate(events):
            prefix = kind if len(events) == 1 else f"{kind}.{i}"
            kick = event if isinstance(event, Kick) else None
            magnitude = values[f"{prefix}.magnitude"]
            disturbances.append(
                {
                    "t": values[f"{prefix}.t"],
                    "body": "base" if kick is None else f"board/{kick.body}",
                    "force": horizontal_force(magnitude, values[f"{prefix}.direction"]),
                    "duration": values[f"{prefix}.duration"],
                    "per_kg": kick is None,  # a push per kg of the rider, a kick in N
                }
            )
    fields["disturbances"] = disturbances
    changes = list(fields["changes"])
    payload = distribution.payload
    if payload is not None:
        mass = values["payload.fraction"] * rider_mass
        if abs(mass) >= MIN_PAYLOAD_KG:
            offset = tuple(values[f"payload.offset.{axis}"] for axis in "xyz")
            changes.append(
                {"parameter": "payload", "body": payload.body, "mass": mass, "offset": offset}
            )
    for change in distribution.changes:
        changes += _changes(change, values)
    fields["changes"] = changes
    if distribution.start is not None:
        foot = fields["foot_offset"]
        fields["foot_offset"] = tuple(
            foot[i] + values[f"start.foot_offset.{axis}"] for i, axis in enumerate("xy")
        )
        if distribution.start.platform_offsets is not None:
            base = fields["platform_offsets"] or ((0.0, 0.0),) * platforms
            fields["platform_offsets"] = tuple(
                tuple(
                    base[p][i] + values[f"start.platform_offsets.{p}.{axis}"]
                    for i, axis in enumerate("xy")
                )
                for p in range(platforms)
            )
    if distribution.steering is not None:
        fields["commands"] = turn_events(distribution.steering, fields["commands"], values)
    if distribution.terrain is not None:
        fields["terrain"] = [*fields["terrain"], *distribution.terrain.items(values)]
    if distribution.noise is not None:
        noise = dict(fields["noise"])
        for key in noise:
            if key.endswith("_std"):
                noise[key] *= values["noise.scale"]
        noise["vio_latency"] *= values["noise.vio_latency_scale"]
        fields["noise"] = noise
    return fields


def _changes(change: DrawnChange, values: Mapping[str, float]) -> list[dict[str, Any]]:
    """A drawn knob as scenario changes: one per body it names (the same draw)."""
    entry: dict[str, Any] = {"t": values[f"{change.label}.t"], "parameter": change.parameter}
    for form in ("value", "scale"):
        if getattr(change, form) is not None:
            entry[form] = values[f"{change.label}.{form}"]
    for where in ("gain", "joint"):
        if getattr(change, where) is not None:
            entry[where] = getattr(change, where)
    return [{**entry, "body": body} for body in change.bodies] or [entry]
