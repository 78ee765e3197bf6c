"""The pushed rides of a push-margin search: one push on the base, added to a base scenario.

Directions lie in the horizontal plane, evenly spaced, counter-clockwise from the rider's
forward (0°: +x of the world, which every rider faces at the start; 90°: its left, +y).
The push is a force per kg of the rider's mass [N/kg] on its base for
:data:`PUSH_DURATION_S`, a scenario ``[[disturbances]]`` entry with ``per_kg = true``.
"""

from __future__ import annotations

from pydantic import ValidationError

from ridempc.errors import ConfigError
from ridempc.scenarios.scenario import Disturbance, Scenario
from ridempc.sweep.variants import horizontal_force

__all__ = [
    "DURATION_AFTER_S",
    "PUSH_DURATION_S",
    "PUSH_TIME_S",
    "direction_key",
    "directions",
    "pushed_scenario",
]

PUSH_DURATION_S: float = 0.2  # [s] the push: short against a rider's sway (~1 s)
# [s] when the push comes, as in the library's push scenarios: after the start-up, when the
# rider has settled on its support (stand-still, peak base speed over 2.5-3 s: 0.003 m/s
# for the dog on the skateboard to 0.12 m/s for Cassie on the Segway, PD), small against
# the 0.2 m/s per N/kg a push gives.
PUSH_TIME_S: float = 3.0
# [s] ridden after the push (a fall ends the ride at once, so only survivors ride it all):
# most falls come within 2.5 s of the push, but of the boundary survivors of 4 s windows
# (stand-still, seed 0), ridden on to 10 s, six fell 4.4-8.4 s after it (Cassie: 5 of 8
# directions on the Segway with the MPC, 1 on the Hovershoes with PD), while the unpushed
# rides stood for 13 s.
DURATION_AFTER_S: float = 10.0
_FORCE_DIGITS: int = 9  # cos(90°) is 6e-17, not 0: the force's components are rounded


def directions(count: int) -> tuple[float, ...]:
    """``count`` directions [deg], evenly spaced from 0 (forward), counter-clockwise."""
    return tuple(360.0 * k / count for k in range(count))


def direction_key(degrees: float) -> str:
    """The direction's name in ``margin.json`` and the rides' folders, e.g. ``45``, ``51.43``."""
    return f"{round(degrees, 2):g}"


def pushed_scenario(
    base: Scenario,
    degrees: float,
    magnitude: float,
    push_time: float = PUSH_TIME_S,
    duration_after: float = DURATION_AFTER_S,
) -> Scenario:
    """``base`` with one push on the base, ridden ``duration_after`` seconds past it.

    Args:
        base: The scenario pushed (its own events stay; its duration is replaced).
        degrees: The push's direction [deg] (module docstring).
        magnitude: The push [N/kg]; 0 adds none (the unpushed ride).
        push_time: When the push starts [s].
        duration_after: Ridden after the push starts [s].

    Returns:
        The checked scenario, named ``<base>-push-<direction>-<magnitude>``.

    Raises:
        ConfigError: The result is not a valid scenario (a base event after the ride's end,
            a push beyond the scenarios' bound), with the field named.
    """
    fields = base.model_dump()
    fields["duration"] = push_time + duration_after
    if magnitude > 0.0:
        force = [round(f, _FORCE_DIGITS) + 0.0 for f in horizontal_force(magnitude, degrees)]
        push = Disturbance(
            t=push_time,
            body="base",
            force=(force[0], force[1], 0.0),
            duration=PUSH_DURATION_S,
            per_kg=True,
        )
        fields["disturbances"] = (*base.disturbances, push)
        fields["name"] = f"{base.name}-push-{direction_key(degrees)}-{magnitude:g}"
    else:
        fields["name"] = f"{base.name}-unpushed"
    fields["description"] = (
        f"{base.name}, ridden to {push_time + duration_after:g} s, with a push of {magnitude:g} "
        f"N/kg for {PUSH_DURATION_S:g} s at {push_time:g} s towards {degrees:g} deg "
        "(0: forward, counter-clockwise)"
        if magnitude > 0.0
        else f"{base.name}, ridden to {push_time + duration_after:g} s, without a push"
    )
    try:
        return Scenario.model_validate(fields)
    except ValidationError as exc:
        raise ConfigError.from_validation(f"scenario '{base.name}' pushed", exc, Scenario) from None
