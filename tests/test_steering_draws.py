"""A turn in a sweep's distribution (ridempc.sweep.steering_draws): a yaw-rate command drawn
per variant, added to the base's commands and back to straight, refused on a base that
steers itself, after the ride's end, or beyond what the board turns. No rides."""

from __future__ import annotations

from pathlib import Path

import pytest

from ridempc.errors import ConfigError
from ridempc.scenarios import load_scenario_file, resolve_scenario
from ridempc.sweep.distribution import load_distribution
from ridempc.sweep.variants import draw_variants, scenario_toml

TURN = """
name = "turn"
[steering]
yaw_rate = {uniform = [-0.3, 0.3]}
t = {uniform = [3.0, 6.0]}
duration = {uniform = [1.0, 2.0]}
"""


def _variants(tmp_path: Path, text: str = TURN, scenario: str = "cruise-0.5", **ride):
    ride = {"robot": "cassie", "board": "hovershoes", "samples": 6, "seed": 1} | ride
    path = tmp_path / "d.toml"
    path.write_text(text)
    return draw_variants(
        resolve_scenario(scenario, ride["board"]),
        load_distribution(str(path), ride["board"]),
        **ride,
    )


def test_the_drawn_turn_is_commanded_then_straight_again(tmp_path: Path) -> None:
    for variant in _variants(tmp_path):
        rate, start = variant.drawn["steering.yaw_rate"], variant.drawn["steering.t"]
        end = start + variant.drawn["steering.duration"]
        scenario = variant.scenario
        assert [c.t for c in scenario.commands] == sorted(c.t for c in scenario.commands)
        assert scenario.command_at(start - 0.01).yaw_rate == 0.0
        assert scenario.command_at(end - 0.01).yaw_rate == pytest.approx(rate)
        assert scenario.command_at(end + 0.5).yaw_rate == 0.0
        assert scenario.command_at(end + 0.5).velocity == 0.5  # the base's speed untouched


def test_a_variant_with_a_turn_reads_back_and_draws_alike(tmp_path: Path) -> None:
    variants = _variants(tmp_path)
    assert [v.drawn for v in _variants(tmp_path, samples=2)] == [v.drawn for v in variants[:2]]
    for variant in variants:
        path = tmp_path / f"{variant.id}.toml"
        path.write_text(scenario_toml(variant.scenario))
        assert load_scenario_file(path) == variant.scenario


@pytest.mark.parametrize(
    ("text", "scenario", "ride", "words"),
    [
        (TURN, "yaw-steps", {}, "field 'steering': scenario 'yaw-steps' commands its own"),
        (TURN.replace("[1.0, 2.0]", "[1.0, 8.0]"), "cruise-0.5", {}, "the turn ends up to 14.5 s"),
        (TURN.replace("[-0.3, 0.3]", "[0.3, -0.3]"), "cruise-0.5", {}, "steering.yaw_rate"),
        (TURN.replace("[-0.3, 0.3]", "[-20.0, 0.3]"), "cruise-0.5", {}, "rad/s"),
        (TURN + "ramp = -1.0\n", "cruise-0.5", {}, "steering.ramp"),
        (TURN, "stand-still", {"board": "skateboard", "robot": "cyberdog2"}, "yaw_rate"),
    ],
)
def test_a_turn_that_cannot_be_ridden_is_refused(tmp_path, text, scenario, ride, words) -> None:
    with pytest.raises(ConfigError) as caught:
        _variants(tmp_path, text, scenario, **ride)
    assert words in str(caught.value) and "\n" not in str(caught.value)
