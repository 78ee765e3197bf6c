"""Terrain in a sweep's distribution (ridempc.sweep.terrain_draws): a slope or a step drawn
per variant from its own generator, checked like every field, written into the variant's
scenario file and read back, named in ``drawn``. No rides."""

from __future__ import annotations

from pathlib import Path

import pytest

from ridempc.cli import main
from ridempc.errors import ConfigError
from ridempc.scenarios import load_scenario_file, resolve_scenario
from ridempc.scenarios.terrain import Slope, Step
from ridempc.sweep.distribution import load_distribution
from ridempc.sweep.variants import draw_variants, scenario_toml

BASE = """
name = "t"
[[pushes]]
magnitude = {uniform = [0.0, 1.0]}
t = {uniform = [0.5, 1.0]}
"""
TERRAIN = """
[terrain]
probability = 0.7
kinds = ["slope", "step"]
start = {uniform = [1.0, 2.0]}
slope_deg = {uniform = [-5.0, 5.0]}
slope_length = 2.0
step_height_radii = {uniform = [-0.6, -0.1]}
"""


def _variants(tmp_path: Path, text: str, samples: int = 40, scenario: str = "cruise-0.5"):
    path = tmp_path / "d.toml"
    path.write_text(text)
    return draw_variants(
        resolve_scenario(scenario, "hovershoes"),
        load_distribution(str(path), "hovershoes"),
        robot="cassie",
        board="hovershoes",
        samples=samples,
        seed=3,
    )


def test_each_variant_rides_the_slope_or_step_it_names(tmp_path: Path) -> None:
    kinds = set()
    for variant in _variants(tmp_path, BASE + TERRAIN):
        drawn, terrain = variant.drawn, variant.scenario.terrain
        assert 1.0 <= drawn["terrain.start"] <= 2.0
        slope, step = drawn["terrain.slope_deg"], drawn["terrain.step_height_radii"]
        assert slope == 0.0 or step == 0.0
        if not terrain:
            kinds.add("level")
            assert slope == step == 0.0
            continue
        (item,) = terrain
        if isinstance(item, Slope):
            kinds.add("slope")
            assert item.start == drawn["terrain.start"] and item.length == 2.0
            assert item.angle == abs(slope) and item.direction == ("up" if slope > 0 else "down")
        else:
            assert isinstance(item, Step)
            kinds.add("step")
            assert item.at == drawn["terrain.start"] and item.direction == "down"
            assert item.height_radii == -step and 0.1 <= item.height_radii <= 0.6
    assert kinds == {"level", "slope", "step"}
    assert "terrain.present" not in drawn and "terrain.kind" not in drawn


def test_no_probability_is_level_ground(tmp_path: Path) -> None:
    text = BASE + TERRAIN.replace("probability = 0.7", "probability = 0.0")
    for variant in _variants(tmp_path, text, samples=5):
        assert variant.scenario.terrain == ()
        assert variant.drawn["terrain.slope_deg"] == variant.drawn["terrain.step_height_radii"] == 0


def test_terrain_is_drawn_after_the_rest_from_the_variants_own_generator(tmp_path: Path) -> None:
    plain = _variants(tmp_path, BASE, samples=5)
    with_terrain = _variants(tmp_path, BASE + TERRAIN, samples=5)
    fewer = _variants(tmp_path, BASE + TERRAIN, samples=2)
    for a, b in zip(plain, with_terrain, strict=True):
        assert a.seed == b.seed and a.drawn.items() <= b.drawn.items()
    assert [v.scenario for v in fewer] == [v.scenario for v in with_terrain[:2]]
    assert [v.drawn for v in fewer] == [v.drawn for v in with_terrain[:2]]


def test_a_variant_with_terrain_reads_back_to_an_equal_scenario(tmp_path: Path) -> None:
    variants = [v for v in _variants(tmp_path, BASE + TERRAIN, samples=10) if v.scenario.terrain]
    assert {type(v.scenario.terrain[0]) for v in variants} == {Slope, Step}
    for variant in variants:
        path = tmp_path / f"{variant.id}.toml"
        path.write_text(scenario_toml(variant.scenario))
        assert load_scenario_file(path) == variant.scenario


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ("slope_length = 2.0", "slope_length = 2.0\nheight = 1", "terrain.height"),
        ("[-5.0, 5.0]", "[5.0, -5.0]", "terrain.slope_deg"),
        ("[-5.0, 5.0]", "[-45.0, 5.0]", "within [-30, 30] deg"),
        ("[1.0, 2.0]", "[0.2, 2.0]", "terrain.start"),
        ('["slope", "step"]', '["slope", "stairs"]', "terrain.kinds"),
        ('["slope", "step"]', "[]", "terrain.kinds"),
        ('["slope", "step"]', '["slope", "slope"]', "names one twice"),
        ('["slope", "step"]', '["step"]', "slope_deg is given exactly when kinds has 'slope'"),
        ("step_height_radii =", "step_height =", "exactly one of step_height [m] or"),
        ("probability = 0.7", "probability = 1.5", "terrain.probability"),
        ("[-0.6, -0.1]", "[-2.5, -0.1]", "a step down higher than board 'hovershoes' can roll"),
        ("[-0.6, -0.1]", "[-0.6, 0.8]", "draws 0.8 wheel radii, a step up"),
    ],
)
def test_bad_terrain_is_refused_naming_the_field(tmp_path: Path, old, new, words) -> None:
    text = BASE + TERRAIN.replace(old, new, 1)
    if old == "step_height_radii =":  # both forms of a step's height
        text += "step_height_radii = {uniform = [-0.6, -0.1]}\n"
    with pytest.raises(ConfigError) as caught:
        _variants(tmp_path, text, samples=1)
    assert words in str(caught.value) and "\n" not in str(caught.value)


def test_terrain_overlapping_the_scenarios_own_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"variant v0000: .*overlaps"):
        _variants(tmp_path, BASE + TERRAIN.replace("0.7", "1.0"), 1, scenario="slope-up-7")


def test_the_sweep_command_refuses_bad_terrain_with_one_line(tmp_path: Path, capsys) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(BASE + TERRAIN.replace("[-5.0, 5.0]", "[5.0, 5.0]"))
    out = tmp_path / "sweep"
    args = ["sweep", "--robot", "cassie", "--board", "hovershoes", "--scenario", "cruise-0.5",
            "--distribution", str(path), "--samples", "2", "--controllers", "pd",
            "--out", str(out)]  # fmt: skip
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("ridempc: error: ") and err.count("\n") == 1
    assert str(path) in err and "terrain.slope_deg" in err and "low < high" in err
    assert not out.exists()
