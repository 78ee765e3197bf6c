"""Variants (ridempc.sweep.variants): drawn reproducibly from the sweep's seed and the
variant's index alone, every quantity within its range, written as scenario files that read
back to equal scenarios, and accepted by every robot that rides the board, at both ends of
every range."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import pytest

from ridempc.boards import load_board
from ridempc.cli import main
from ridempc.controllers.pd import PD_BASELINES
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.robots import load_robot, robot_names
from ridempc.run import RideRequest, check_request
from ridempc.scenarios import load_scenario_file, resolve_scenario
from ridempc.sweep.distribution import Distribution, Law, load_distribution
from ridempc.sweep.terrain_draws import CHOICES as TERRAIN_CHOICES
from ridempc.sweep.tomltext import toml_text
from ridempc.sweep.variants import draw_variants, scenario_toml

BOARDS = ("hovershoes", "segway", "skateboard")


def _riders(board: str) -> list[str]:
    """The robots that ride ``board``: those with a PD baseline for its kind."""
    loaded = load_board(board)
    assert loaded is not None
    kind = loaded.params.kind
    return [r for r in robot_names() if (load_robot(r).params.kind, kind) in PD_BASELINES]


def _draw(board: str, name: str, samples: int, seed: int = 0, scenario: str = "push"):
    robot = _riders(board)[0]
    return draw_variants(
        resolve_scenario(scenario, board),
        load_distribution(name, board),
        robot=robot,
        board=board,
        samples=samples,
        seed=seed,
    )


def _at_end(distribution: Distribution, end: int) -> Distribution:
    """The distribution with every law fixed at its lowest (0) or highest (1) draw."""
    fields = set(Law.model_fields)

    def fixed(node: Any) -> Any:
        if isinstance(node, dict) and set(node) == fields:
            return Law.model_validate(node).bounds()[end]
        if isinstance(node, dict):
            return {k: fixed(v) for k, v in node.items() if v is not None}
        if isinstance(node, list | tuple):
            return [fixed(v) for v in node]
        return node

    return Distribution.model_validate(fixed(distribution.model_dump()))


def test_the_same_seed_gives_the_same_variants_and_more_samples_extend_them() -> None:
    first = _draw("hovershoes", "hard", 3, seed=11)
    again = _draw("hovershoes", "hard", 6, seed=11)
    assert again[:3] == first
    assert [v.id for v in again] == ["v0000", "v0001", "v0002", "v0003", "v0004", "v0005"]
    other = _draw("hovershoes", "hard", 3, seed=12)
    assert all(a.drawn != b.drawn and a.seed != b.seed for a, b in zip(first, other, strict=True))
    assert len({v.seed for v in again}) == 6


def test_a_variant_is_named_after_its_scenario_and_id() -> None:
    variant = _draw("segway", "everyday", 2)[1]
    assert variant.index == 1 and variant.scenario.name == "push-v0001"
    assert "everyday" in variant.scenario.description
    assert 0 <= variant.seed <= 2**32 - 1


@pytest.mark.parametrize("board", BOARDS)
@pytest.mark.parametrize("name", ["everyday", "hard", "everyday-terrain", "hard-terrain"])
def test_every_drawn_quantity_lies_in_its_range(board: str, name: str) -> None:
    distribution = load_distribution(name, board)
    laws = distribution.quantities(platforms=2 if board == "hovershoes" else 0)
    variants = _draw(board, name, 20)
    random = {k for k, law in laws.items() if law.random} - set(TERRAIN_CHOICES)
    for variant in variants:
        assert set(variant.drawn) == random
        for key, value in variant.drawn.items():
            low, high = laws[key].bounds()
            flat = key.startswith("terrain.") and value == 0.0  # level ground drawn
            assert flat or low <= value <= high, key


def test_the_draws_reach_the_scenario() -> None:
    base = resolve_scenario("push", "hovershoes")
    variant = _draw("hovershoes", "hard", 1)[0]
    drawn, scenario = variant.drawn, variant.scenario
    added = scenario.disturbances[len(base.disturbances) :]
    assert [d.body for d in added] == ["base", "board/left_shoe", "board/right_shoe"]
    push = added[0]
    assert push.per_kg and push.t == drawn["push.t"] and push.duration == drawn["push.duration"]
    assert sum(f * f for f in push.force) == pytest.approx(drawn["push.magnitude"] ** 2)
    payload = next(c for c in scenario.changes if c.parameter == "payload")
    assert payload.mass == pytest.approx(drawn["payload.fraction"] * load_robot("cassie").mass)
    masses = [c for c in scenario.changes if c.parameter == "board_mass"]
    assert [c.body for c in masses] == ["left_shoe", "right_shoe"]
    assert {c.scale for c in masses} == {drawn["changes.board_mass.left_shoe+right_shoe.scale"]}
    assert scenario.noise.imu_gyro_std == pytest.approx(
        base.noise.imu_gyro_std * drawn["noise.scale"]
    )
    assert scenario.foot_offset[0] == pytest.approx(
        base.foot_offset[0] + drawn["start.foot_offset.x"]
    )
    assert len(scenario.platform_offsets) == 2


@pytest.mark.parametrize("board", BOARDS)
def test_a_variant_file_reads_back_to_an_equal_scenario(board: str, tmp_path: Path) -> None:
    for variant in _draw(board, "hard", 3, seed=5):
        path = tmp_path / f"{variant.id}.toml"
        path.write_text(scenario_toml(variant.scenario))
        assert load_scenario_file(path) == variant.scenario
        assert resolve_scenario(str(path), board) == variant.scenario


@pytest.mark.parametrize("board", BOARDS)
@pytest.mark.parametrize("name", ["everyday", "hard"])
def test_every_rider_of_the_board_takes_both_ends_of_every_range(board: str, name: str) -> None:
    """The variants at the lowest and at the highest draws pass every check of a ride:
    the knobs against the built scene and the board's parameter model."""
    distribution = load_distribution(name, board)
    for robot in _riders(board):
        for end in (0, 1):
            (variant,) = draw_variants(
                resolve_scenario("stand-still", board),
                _at_end(distribution, end),
                robot=robot,
                board=board,
                samples=1,
                seed=0,
            )
            check_request(RideRequest(robot, board, "pd", variant.scenario, None))


def test_ridempc_sim_rides_a_variant_file(tmp_path: Path, capsys) -> None:
    (variant,) = _draw("skateboard", "hard", 1, seed=3)
    path = tmp_path / f"{variant.id}.toml"
    path.write_text(scenario_toml(variant.scenario))
    argv = ["sim", "--robot", "cyberdog2", "--board", "skateboard", "--controller", "pd"]
    argv += ["--scenario", str(path), "--seed", str(variant.seed), "--duration", "0.3"]
    assert main([*argv, "--out", str(tmp_path / "ride"), "--no-plots"]) == 0
    assert f"'{variant.scenario.name}' seed {variant.seed}" in capsys.readouterr().out


@pytest.mark.parametrize(
    "change, words",
    [
        ({"samples": 0}, "--samples 0: allowed: an integer of at least 1"),
        ({"samples": 2.0}, "--samples 2.0"),
        ({"seed": -1}, "--seed -1: allowed"),
        ({"seed": 2**32}, "--seed 4294967296: allowed"),
        ({"board": "segway"}, "is for board 'hovershoes'; allowed: one for board 'segway'"),
        ({"robot": "walle"}, "unknown robot 'walle'"),
    ],
)
def test_bad_arguments_are_refused(change: dict[str, Any], words: str) -> None:
    call: dict[str, Any] = {"robot": "cassie", "board": "hovershoes", "samples": 2, "seed": 0}
    scenario = resolve_scenario("push", "hovershoes")
    distribution = load_distribution("everyday", "hovershoes")
    with pytest.raises((ConfigError, UnknownNameError)) as caught:
        draw_variants(scenario, distribution, **(call | change))
    assert words in str(caught.value)


def test_an_event_after_the_rides_end_is_refused() -> None:
    scenario = resolve_scenario("push", "segway").with_duration(5.0)
    with pytest.raises(ConfigError, match=r"field 'pushes.0.t': draws up to 8 s; allowed: within"):
        draw_variants(
            scenario,
            load_distribution("everyday", "segway"),
            robot="cassie",
            board="segway",
            samples=1,
            seed=0,
        )


def test_doubled_noise_beyond_a_sensors_bound_is_refused_naming_the_field(tmp_path: Path) -> None:
    base = resolve_scenario("stand-still", "segway")
    noisy = base.model_copy(update={"noise": base.noise.model_copy(update={"vio_latency": 0.9})})
    path = tmp_path / "noisy.toml"
    path.write_text('name = "noisy"\n[noise]\nvio_latency_scale = 2.0\n')
    with pytest.raises(ConfigError, match="variant v0000: field 'noise.vio_latency'"):
        draw_variants(
            noisy,
            load_distribution(str(path), "segway"),
            robot="cassie",
            board="segway",
            samples=1,
            seed=0,
        )


def test_toml_text_writes_strings_and_numbers_exactly() -> None:
    table = {
        "name": 'a "quoted"\nline\t\\ é \x7f',
        "numbers": [0.1, 1e-300, 1.7976931348623157e308, -0.0, 3, True],
        "nested": [[1.0, 2.0], []],
        "table": {"key with space": 1.5},
        "rows": [{"t": 1.0}, {"t": 2.0, "sub": {"x": 0.30000000000000004}}],
    }
    read = tomllib.loads(toml_text(table))
    assert read == table
    with pytest.raises(ValueError, match="finite"):
        toml_text({"x": float("nan")})
