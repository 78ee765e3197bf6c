"""Pair files (``pairs/<robot>-<board>.toml``): every committed one loads and builds, and a
bad one is one line naming the file and the field, before anything runs."""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

import pytest

from ridempc import cli
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.library.store import library_folder
from ridempc.mpc.pairs import check_library_names, load_mpc_pair, mpc_pair_names
from ridempc.mpc.reference import select_reference
from ridempc.pair_description import (
    STAGE_NEEDS,
    PushWeightsStage,
    Stages,
    load_pair_description,
    pair_description_names,
    read_pair_file,
)
from ridempc.paths import motion_library_dir, pairs_dir
from ridempc.trajopt.pairs import load_pair, pair_names

PAIRS = pair_description_names()


def test_the_pairs_are_the_files_found() -> None:
    files = sorted(p.stem for p in pairs_dir().glob("*.toml"))
    assert list(PAIRS) == files == list(pair_names()) == list(mpc_pair_names())
    assert {"cassie-hovershoes", "cassie-segway", "cyberdog2-skateboard"} <= set(PAIRS)


def test_every_stage_says_what_it_needs() -> None:
    assert set(STAGE_NEEDS) == set(Stages.model_fields)


@pytest.mark.parametrize("name", PAIRS)
def test_each_pair_file_loads_and_builds(name: str) -> None:
    robot, board = name.split("-", 1)
    description = load_pair_description(robot, board)
    assert description.name == name
    mpc = load_mpc_pair(robot, board)
    assert mpc.description == description
    assert mpc.pyramid == description.mpc.pyramid
    assert mpc.plan_latency == description.mpc.plan_latency
    assert load_pair(robot, board).default_targets == description.trajopt.default_targets


def test_the_stages_become_the_mpc_pairs_settings() -> None:
    """The numbers the rider rides with are the pair files' (the three committed pairs)."""
    shoes = load_mpc_pair("cassie", "hovershoes")
    assert shoes.force_time_constant == pytest.approx(0.042)
    assert len(shoes.tipping) == 2 and shoes.terminal_factor == pytest.approx(30.0)
    segway = load_mpc_pair("cassie", "segway")
    assert segway.tipping == () and segway.force_time_constant is None
    assert segway.description.mpc.unrealised_inputs == ("knee_bar",)
    deck = load_mpc_pair("cyberdog2", "skateboard")
    assert deck.roll_observer == pytest.approx(0.3) and deck.stance_roll == pytest.approx(0.42)
    assert deck.roll_lead == pytest.approx(0.08) and deck.settle is not None
    assert dict(deck.push_tolerances) == {"vx": 0.0125, "board_v": 0.05}


def test_the_names_a_pair_file_gives_are_its_librarys() -> None:
    """Push tolerances name states, unrealised inputs name inputs of the pair's library
    (checked when the rider is built, before the ride)."""
    description = load_pair_description("cyberdog2", "skateboard")
    reference = select_reference("cyberdog2", "skateboard", "accelerate", 0.5)
    check_library_names(description, reference)
    mpc = description.mpc.model_copy(update={"unrealised_inputs": ("knee_bar",)})
    with pytest.raises(ConfigError, match="field 'mpc.unrealised_inputs': 'knee_bar'"):
        check_library_names(description.model_copy(update={"mpc": mpc}), reference)
    push = PushWeightsStage(tolerances={"board_speed": 0.05}, max_target=0.7)
    stages = description.stages.model_copy(update={"push_weights": push})
    with pytest.raises(ConfigError, match="'stages.push_weights.tolerances.board_speed'"):
        check_library_names(description.model_copy(update={"stages": stages}), reference)


def test_the_library_folder_is_the_one_the_pair_file_names(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert library_folder("cassie", "segway") == motion_library_dir() / "cassie-segway"
    assert library_folder("cassie", "skateboard").name == "cassie-skateboard"  # no pair file
    folder = tmp_path / "pairs"
    shutil.copytree(pairs_dir(), folder)
    path = folder / "cassie-segway.toml"
    path.write_text(path.read_text().replace('library = "cassie-segway"', 'library = "other"'))
    monkeypatch.setattr("ridempc.pair_description.pairs_dir", lambda: folder)
    load_pair_description.cache_clear()
    try:
        assert library_folder("cassie", "segway", tmp_path) == tmp_path / "other"
    finally:
        load_pair_description.cache_clear()


def test_an_undescribed_pair_is_an_unknown_name() -> None:
    with pytest.raises(UnknownNameError, match="cassie-hovershoes"):
        load_pair_description("cassie", "skateboard")


def _edited(tmp_path: Path, name: str, old: str, new: str) -> Path:
    text = (pairs_dir() / f"{name}.toml").read_text()
    assert old in text
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize(
    ("name", "old", "new", "message"),
    [
        (
            "cassie-hovershoes",
            "[stages.guidance]",
            "[stages.guidance]\n[stages.wobble]",
            "pairs/cassie-hovershoes.toml: field 'stages.wobble': unknown key; allowed: tipping",
        ),
        (
            "cassie-hovershoes",
            "time_constant = 0.042",
            "",
            "field 'stages.force_filter.time_constant': Field required",
        ),
        (
            "cassie-hovershoes",
            "[stages.guidance]",
            "[stages.guidance]\n[stages.lean]",
            "field 'stages.lean': needs a board with knee_bar; board 'hovershoes' has shoes",
        ),
        (
            "cassie-segway",
            "[stages.lean]",
            "[stages.lean]\n[stages.roll_lead]\nlead = 0.08",
            "field 'stages.roll_lead': needs a board with deck_roll",
        ),
        (
            "cassie-hovershoes",
            "[stages.shoe_observer]",
            "",
            "stage 'shoe_heading' needs the stage 'shoe_observer'",
        ),
        (
            "cassie-segway",
            "plan_latency = 2",
            "plan_latency = 15",
            "field 'mpc.plan_latency': Input should be less than 15, got 15",
        ),
        ("cassie-segway", 'pyramid = "box"', 'pyramid = "cone"', "pyramid 'cone': allowed: box"),
        (
            "cassie-hovershoes",
            "longest_wait = 2.0",
            "",
            "field 'stages.takeover.longest_wait': Field required",
        ),
        (
            "cassie-hovershoes",
            "window = 0.3",
            "window = -0.3",
            "field 'stages.takeover.window': Input should be greater than 0",
        ),
        (
            "cassie-segway",
            '"left_hip_pitch", "right_hip_pitch"',
            '"left_hip", "right_hip_pitch"',
            "field 'trajopt.hips': 'left_hip' is not a motor of cassie",
        ),
        ("cassie-segway", 'board = "segway"', 'board = "hovershoes"', "field 'robot'"),
        ("cyberdog2-skateboard", "[mpc]", "[mpc]\nhorizon = 12", "field 'mpc.horizon'"),
        ("cassie-hovershoes", "band = 0.3", "band = -0.3", "field 'stages.impulse.band'"),
        (
            "cyberdog2-skateboard",
            'pusher = "RL_contact"',
            'pusher = "RL_foot"',
            "field 'trajopt.pusher': 'RL_foot' is not a contact site of cyberdog2",
        ),
        ("cyberdog2-skateboard", 'pusher = "RL_contact"', "", "needs the pushing foot's"),
        ("cassie-segway", "force_weight = 1000.0", 'force_weight = "1000"', "force_weight"),
        (
            "cassie-segway",
            'ride_keyframe = "ride_segway_crouch"',
            'ride_keyframe = "crouch"',
            "field 'ride_keyframe': 'crouch' is not a keyframe of cassie; allowed: ",
        ),
        (
            "go1-skateboard",
            'pd_gains = "quadruped_skateboard.go1.toml"',
            'pd_gains = "quadruped_skateboard.go2.toml"',
            "field 'pd_gains': 'quadruped_skateboard.go2.toml' is not a gains file in "
            "ridempc/baselines/; allowed: cassie_hovershoes.toml",
        ),
        (
            "go1-skateboard",
            'pd_gains = "quadruped_skateboard.go1.toml"',
            'pd_gains = "../quadruped_skateboard.go1.toml"',
            "field 'pd_gains': String should match pattern",
        ),
    ],
)
def test_a_bad_pair_file_names_the_file_and_the_field(
    tmp_path: Path, name: str, old: str, new: str, message: str
) -> None:
    with pytest.raises(ConfigError) as caught:
        read_pair_file(_edited(tmp_path, name, old, new))
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_the_committed_files_are_plain_toml() -> None:
    for name in PAIRS:
        raw = tomllib.loads((pairs_dir() / f"{name}.toml").read_text())
        assert f"{raw['robot']}-{raw['board']}" == name


def test_sim_stops_on_a_bad_pair_file_before_anything_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``ridempc sim --controller mpc`` with a bad pair file: exit 2, one line naming the
    file and the field, and nothing written."""
    folder = tmp_path / "pairs"
    shutil.copytree(pairs_dir(), folder)
    path = folder / "cassie-segway.toml"
    path.write_text(path.read_text().replace("[stages.lean]", "[stages.lean]\n[stages.wobble]"))
    monkeypatch.setattr("ridempc.pair_description.pairs_dir", lambda: folder)
    for cached in (load_pair_description, load_mpc_pair, load_pair):
        cached.cache_clear()
    try:
        out = tmp_path / "out"
        code = cli.main(
            [
                "sim",
                "--robot",
                "cassie",
                "--board",
                "segway",
                "--controller",
                "mpc",
                "--scenario",
                "stand-still",
                "--duration",
                "0.1",
                "--out",
                str(out),
                "--no-plots",
            ]
        )
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2
        assert len(err) == 1
        assert err[0].startswith("ridempc: error: pairs/cassie-segway.toml: field 'stages.wobble'")
        assert not out.exists() or not any(out.iterdir())
    finally:
        for cached in (load_pair_description, load_mpc_pair, load_pair):
            cached.cache_clear()
