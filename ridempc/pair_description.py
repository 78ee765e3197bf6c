"""A robot-board pair's description file (``pairs/<robot>-<board>.toml``), checked.

A pair file names its robot, its board and its motion library, the trajectory problem that
builds the library, the MPC's and the whole-body QP's settings, and the stages of the MPC
rider it uses (per-pair mechanisms, each with its parameters). The pairs that exist are the
files found in ``pairs/``; nothing in the code lists them.

A stage needs features of the board (:attr:`ridempc.boards.kinds.BoardKind.features`) and
maybe other stages: a stage that does not fit the board, an unknown stage, a missing or
non-physical parameter is a :class:`~ridempc.errors.ConfigError` naming the file and the
field, raised before anything is built or simulated.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, model_validator

from ridempc.errors import ConfigError, UnknownNameError
from ridempc.friction import SHAPES
from ridempc.paths import pairs_dir
from ridempc.tomlfile import read_toml, validate
from ridempc.units import (
    CheckedModel,
    Flag,
    NonNegative,
    NonNegativeCount,
    Positive,
    Real,
)

__all__ = [
    "STAGE_NEEDS",
    "MpcSection",
    "PairDescription",
    "Stages",
    "TrajoptSection",
    "WbcSection",
    "check_pair_fits",
    "load_pair_description",
    "pair_description_names",
    "pair_file",
    "read_pair_file",
]

MPC_DIVIDER_TICKS: int = 15  # control ticks per MPC step: a plan is due within one step
MAX_SPEED: float = 20.0  # [m/s] beyond any board's; a bound on target speeds
MAX_OPTION: float = 1e6  # beyond any option's figure in its units (weights reach 1e2)

Speed = Annotated[Positive, Field(le=MAX_SPEED, description="[m/s]")]
OptionValue = Annotated[Real, Field(ge=-MAX_OPTION, le=MAX_OPTION)]
Fraction = Annotated[Real, Field(ge=0.0, le=1.0)]


class _Frozen(CheckedModel):
    """Frozen, unknown keys refused, numbers finite and given as numbers."""


class TrajoptSection(_Frozen):
    """How the pair's motion library is built (``ridempc library build``)."""

    problem: Literal["ride", "skate"] = Field(
        description=(
            "The trajectory problem: ``ride``, a biped on a wheeled board "
            "(:mod:`ridempc.trajopt.ride_problem`); ``skate``, a quadruped pushing a "
            "skateboard (:mod:`ridempc.trajopt.skate_problem`)."
        )
    )
    default_targets: tuple[Speed, ...] = Field(
        min_length=1, description="Target speeds of the committed library [m/s]."
    )
    options: dict[str, OptionValue] = Field(
        default_factory=dict,
        description="The problem's numeric option fields (RideOptions, SkateOptions).",
    )
    hips: tuple[str, ...] = Field(
        default=(), description="``ride``: the simplified rider's hip-pitch joints."
    )
    leg_range: tuple[Positive, Positive] = Field(
        default=(0.85, 1.03),
        description="``ride``: leg lengths allowed, as fractions of the riding stance's [-].",
    )
    pusher: str | None = Field(
        default=None, description="``skate``: the contact site of the pushing foot."
    )

    @model_validator(mode="after")
    def _names_the_problem_needs(self) -> TrajoptSection:
        if self.problem == "ride" and not self.hips:
            raise ValueError("a 'ride' problem needs the rider's hips (hip-pitch joints)")
        if self.problem == "skate" and self.pusher is None:
            raise ValueError("a 'skate' problem needs the pushing foot's contact site, pusher")
        if not self.leg_range[0] < self.leg_range[1] <= 2.0:
            raise ValueError(
                f"leg_range {self.leg_range}: the first below the second, both at most 2"
            )
        return self

    def problem_options(self) -> dict[str, float | str]:
        """The problem's option defaults for this pair: its numbers and its pusher."""
        named = {"pusher": self.pusher} if self.pusher is not None else {}
        return {**self.options, **named}


class MpcSection(_Frozen):
    """The MPC's settings for the pair (:class:`ridempc.mpc.pairs.MpcPair`)."""

    pyramid: str = Field(description=f"Friction pyramid shape, one of {', '.join(SHAPES)}.")
    terminal_factor: Positive = Field(
        le=1e4, description="Terminal weight over the stage weight, Q_N = this x Q [-]."
    )
    start_speed: NonNegative = Field(
        le=1.0, description="An accelerate from rest starts at this speed [m/s]."
    )
    speed_preview: Flag = Field(description="Follow the speed planned a horizon ahead.")
    plan_latency: NonNegativeCount = Field(
        lt=MPC_DIVIDER_TICKS,
        description="Control ticks from a solve's state to the tick its plan takes over.",
    )
    predict_start: Flag = Field(
        default=True,
        description="Solve a late plan from the state predicted at its take-up (mpc/delay.py).",
    )
    handover_deviation: Positive = Field(
        default=3.0,
        le=10.0,
        description="The state's error, in its tolerances, beyond which the ride is handed to "
        "the PD (mpc/handover.py): the PD's basin; default the edge of the MPC's model.",
    )
    handover_from_sent: Flag = Field(
        default=False,
        description="A handover blends out of the command sent the tick before, not the failing "
        "tick's own (mpc/handover.py).",
    )
    unrealised_inputs: tuple[str, ...] = Field(
        default=(), description="Board inputs the rider does not realise, held at zero."
    )
    ground_rate_filter: Positive | None = Field(
        default=None,
        le=10.0,
        description="Lag of the followed ground's rise rate [s] (mpc/state_map.py).",
    )

    @model_validator(mode="after")
    def _known_pyramid(self) -> MpcSection:
        if self.pyramid not in SHAPES:
            raise ValueError(f"pyramid '{self.pyramid}': allowed: {', '.join(SHAPES)}")
        return self


class WbcSection(_Frozen):
    """The MPC rider's whole-body QP and motor PD settings for the pair."""

    force_weight: Positive = Field(
        le=1e6,  # beyond it the QP's other tasks vanish below OSQP's tolerances
        description="Weight of the MPC's contact forces in the QP [(kg/N)^2].",
    )
    tracking_gain_scale: Positive = Field(
        le=1.0, description="Fraction of the motors' PD gains about the QP's targets [-]."
    )
    feedforward: Fraction = Field(
        description="Share of the plan's first-step accelerations fed forward [-]."
    )


class Used(_Frozen):
    """A stage without parameters: present means used."""


class ForceFilterStage(_Frozen):
    time_constant: Positive = Field(le=1.0, description="Low-pass on the forces [s].")


class RollObserverStage(_Frozen):
    gain: Positive = Field(le=1.0, description="beta of the torque estimate [-].")


class StanceStage(_Frozen):
    roll_offset: Positive = Field(le=10.0, description="CoM offset per radian of roll [m/rad].")


class RollLeadStage(_Frozen):
    lead: NonNegative = Field(le=1.0, description="Commanded roll read this far ahead [s].")


class SwingForceStage(_Frozen):
    force_step: Positive = Field(le=1e4, description="Tolerance of a deck force's change [N].")


class PushWeightsStage(_Frozen):
    tolerances: dict[str, Annotated[Positive, Field(le=100.0)]] = Field(
        min_length=1, description="Accepted deviation of states over a push-off, by name."
    )
    max_target: Speed = Field(description="Largest push-off target they apply to [m/s].")


class SettleStage(_Frozen):
    duration: Positive = Field(le=10.0, description="Settle over the feet in this [s].")


class PayloadStage(_Frozen):
    mass_from: Literal["loads", "prediction", "start"] = Field(
        default="loads",
        description="The rider's mass weighed by the feet's loads, by the MPC's vertical "
        "prediction error, or once at the ride's first tick (mpc/start_weight.py).",
    )
    start_reading: Positive | None = Field(
        default=None,
        le=10.0,
        description="The nominal rider's first load reading [-] (mass_from 'start').",
    )

    @model_validator(mode="after")
    def _start_calibrated(self) -> PayloadStage:
        if (self.mass_from == "start") != (self.start_reading is not None):
            raise ValueError("start_reading: given with mass_from 'start' and only then")
        return self


class DisturbanceStage(_Frozen):
    time_constant: Positive = Field(le=10.0, description="Low-pass of the estimate [s].")
    max_linear: Positive = Field(le=100.0, description="Bound on a linear row [m/s^2].")
    max_angular: Positive = Field(le=1000.0, description="Bound on an angular row [rad/s^2].")
    rows: tuple[Literal["horizontal", "vertical", "angular", "board"], ...] = Field(
        default=("horizontal", "vertical", "angular", "board"),
        min_length=1,
        description="Rows estimated.",
    )


class TakeoverStage(_Frozen):
    window: Positive = Field(le=10.0, description="Estimates' change measured over this [s].")
    mass_change: Positive = Field(
        le=1.0, description="Largest change of the payload's mass over the window [-]."
    )
    shift_change: Positive = Field(
        le=0.5, description="Largest change of the centre of mass's offset over it [m]."
    )
    longest_wait: Positive = Field(le=60.0, description="The MPC takes over by then [s].")
    by_prediction: bool = Field(
        default=False,
        description="The MPC is proven (off probation) only once its plans' predictions hold.",
    )


class FlightStage(_Frozen):
    extend_speed: Speed = Field(description="How fast the feet reach down after the shoes [m/s].")
    max_extension: Positive = Field(le=0.5, description="How far they reach at most [m].")
    landing: Positive | None = Field(
        default=None,
        le=1.0,
        description="How long each foot's load stays centred on its shoe after a landing [s].",
    )
    landing_depth: NonNegative = Field(
        default=0.0,
        le=0.5,
        description="The shallowest fall whose landing is ridden flat-footed [m].",
    )


class ImpulseStage(_Frozen):
    band: Speed = Field(description="Largest unexplained velocity change the MPC rides [m/s].")
    sideways: Speed | None = Field(default=None, description="The same across it [m/s].")
    divergence_blend: bool = Field(
        default=False,
        description="A push's handover blended over the rider's divergence time, not the "
        "handover's own blend (mpc/push_handover.py).",
    )


class Stages(_Frozen):
    """The MPC rider's per-pair stages; a stage left out is not used."""

    tipping: Used | None = None
    force_filter: ForceFilterStage | None = None
    shoe_observer: Used | None = None
    shoe_heading: Used | None = None
    guidance: Used | None = None
    slope_trim: Used | None = None
    lean: Used | None = None
    roll_steering: Used | None = None
    roll_observer: RollObserverStage | None = None
    stance: StanceStage | None = None
    roll_lead: RollLeadStage | None = None
    swing_force_hold: SwingForceStage | None = None
    push_weights: PushWeightsStage | None = None
    settle: SettleStage | None = None
    payload: PayloadStage | None = None
    disturbance: DisturbanceStage | None = None
    takeover: TakeoverStage | None = None
    drop: Used | None = None
    flight: FlightStage | None = None
    impulse: ImpulseStage | None = None

    def used(self) -> tuple[str, ...]:
        """The names of the stages used, in declaration order."""
        return tuple(name for name in type(self).model_fields if getattr(self, name) is not None)


# Per stage, the board features (BoardKind.features) and the other stages it needs.
STAGE_NEEDS: dict[str, tuple[frozenset[str], tuple[str, ...]]] = {
    "tipping": (frozenset({"shoes"}), ()),
    "force_filter": (frozenset(), ()),
    "shoe_observer": (frozenset({"shoes"}), ()),
    "shoe_heading": (frozenset({"shoes"}), ("shoe_observer",)),
    "guidance": (frozenset({"shoes"}), ("shoe_observer",)),
    "slope_trim": (frozenset({"shoes"}), ("shoe_observer",)),
    "lean": (frozenset({"knee_bar"}), ()),
    "roll_steering": (frozenset({"deck_roll"}), ()),
    "roll_observer": (frozenset({"deck_roll"}), ()),
    "stance": (frozenset({"deck_roll"}), ("roll_observer",)),
    "roll_lead": (frozenset({"deck_roll"}), ()),
    "swing_force_hold": (frozenset(), ()),
    "push_weights": (frozenset(), ()),
    "settle": (frozenset(), ()),
    "payload": (frozenset(), ()),
    "disturbance": (frozenset(), ()),
    "takeover": (frozenset(), ()),
    "drop": (frozenset(), ()),
    "flight": (frozenset(), ("drop",)),
    "impulse": (frozenset(), ()),
}


class PairDescription(_Frozen):
    """Checked, immutable description of one robot-board pair (``pairs/<robot>-<board>.toml``)."""

    robot: str = Field(pattern=r"^[a-z0-9][a-z0-9_-]*$")
    board: str = Field(pattern=r"^[a-z0-9][a-z0-9_-]*$")
    library: str = Field(
        pattern=r"^[a-z0-9][a-z0-9_.-]*$",
        description="The motion library's folder in ``motion_library/``.",
    )
    bench_scenario: str = Field(
        default="stand-still",
        pattern=r"^[a-z0-9][a-z0-9_.-]*$",
        description=(
            "The scenario ``ridempc bench`` records: a manoeuvre, where the QPs are hardest."
        ),
    )
    ride_keyframe: str | None = Field(
        default=None,
        pattern=r"^[A-Za-z0-9_.-]+$",
        description=(
            "The keyframe of the robot's description the MPC rider rides in, where it is "
            "not its stance on the board (Cassie crouches on the Segway to reach the knee bar)."
        ),
    )
    pd_gains: str | None = Field(
        default=None,
        pattern=r"^[a-z0-9][a-z0-9_.-]*\.toml$",
        description=(
            "The PD baseline's gains file, in ``ridempc/baselines/``; left out, the "
            "baseline's default (a quadruped's: the CyberDog2's figures)."
        ),
    )
    trajopt: TrajoptSection
    mpc: MpcSection
    wbc: WbcSection
    stages: Stages = Field(default_factory=Stages)

    @property
    def name(self) -> str:
        return f"{self.robot}-{self.board}"

    @model_validator(mode="after")
    def _options_known(self) -> PairDescription:
        allowed = problem_option_names(self.trajopt.problem)
        for key in self.trajopt.options:
            if key not in allowed:
                raise ValueError(
                    f"field 'trajopt.options.{key}': unknown key; allowed: {', '.join(allowed)}"
                )
        return self

    @model_validator(mode="after")
    def _stages_have_their_stages(self) -> PairDescription:
        used = set(self.stages.used())
        for stage in self.stages.used():
            missing = [s for s in STAGE_NEEDS[stage][1] if s not in used]
            if missing:
                raise ValueError(f"stage '{stage}' needs the stage '{missing[0]}'")
        return self


def problem_option_names(problem: str) -> tuple[str, ...]:
    """The numeric option fields of a trajectory problem (``RideOptions``, ``SkateOptions``)."""
    import dataclasses

    from ridempc.trajopt.ride_problem import RideOptions
    from ridempc.trajopt.skate_problem import SkateOptions

    options = {"ride": RideOptions, "skate": SkateOptions}[problem]
    return tuple(f.name for f in dataclasses.fields(options) if f.type in ("float", float))


def pair_description_names() -> tuple[str, ...]:
    """The pairs described, ``<robot>-<board>``, from the files found in ``pairs/``."""
    folder = pairs_dir()
    if not folder.is_dir():
        return ()
    return tuple(sorted(p.stem for p in folder.glob("*.toml")))


def pair_file(robot: str, board: str) -> Path:
    return pairs_dir() / f"{robot}-{board}.toml"


@cache
def load_pair_description(robot: str, board: str) -> PairDescription:
    """The checked description of ``robot`` on ``board``, read once per process.

    Raises:
        UnknownNameError: No file describes that pair; the message lists the pairs described.
        ConfigError: The file is malformed, a setting or parameter is missing or
            non-physical, a stage is unknown or lacks a stage it needs, the file names
            another pair, or a stage does not fit the board (:func:`check_pair_fits`).
    """
    name = f"{robot}-{board}"
    if name not in pair_description_names():
        raise UnknownNameError("robot-board pair", name, pair_description_names())
    return read_pair_file(pair_file(robot, board))


def read_pair_file(path: Path) -> PairDescription:
    """Read and check one pair file, named ``<robot>-<board>.toml`` for the pair it describes.

    Raises:
        ConfigError: As :func:`load_pair_description`; the message names the file as
            ``pairs/<name>.toml`` and the field.
    """
    shown = Path("pairs") / path.name
    description = validate(shown, read_toml(path, "pair file"), PairDescription)
    if path.stem != description.name:
        raise ConfigError(
            f"{shown}: field 'robot': the file describes {description.name}; allowed: the "
            f"pair its name says, {path.stem}"
        )
    check_pair_fits(description, shown)
    return description


def check_pair_fits(description: PairDescription, shown: Path | str) -> None:
    """Every stage of ``description`` fits its board, and its names exist in the robot.

    Raises:
        ConfigError: A stage needs a board feature the board lacks, ``pd_gains`` names no
            gains file, or a hip joint, the pusher or the ride keyframe is not in the robot's
            description.
    """
    from ridempc.boards import load_board
    from ridempc.robots import load_robot

    board = load_board(description.board)
    features = board.kind.features if board is not None else frozenset()
    for stage in description.stages.used():
        lacking = sorted(STAGE_NEEDS[stage][0] - features)
        if lacking:
            raise ConfigError(
                f"{shown}: field 'stages.{stage}': needs a board with {lacking[0]}; board "
                f"'{description.board}' has {', '.join(sorted(features)) or 'none'}"
            )
    _check_pd_gains(description, shown)
    robot = load_robot(description.robot)
    model = robot.mj_model
    keyframes = [model.key(i).name for i in range(model.nkey)]
    if description.ride_keyframe is not None and description.ride_keyframe not in keyframes:
        raise ConfigError(
            f"{shown}: field 'ride_keyframe': '{description.ride_keyframe}' is not a keyframe "
            f"of {description.robot}; allowed: {', '.join(keyframes)}"
        )
    pusher, sites = description.trajopt.pusher, robot.params.contact_sites
    if pusher is not None and pusher not in sites:
        raise ConfigError(
            f"{shown}: field 'trajopt.pusher': '{pusher}' is not a contact site of "
            f"{description.robot}; allowed: {', '.join(sites)}"
        )
    joints = set(robot.params.motors)
    for hip in description.trajopt.hips:
        if hip not in joints:
            raise ConfigError(
                f"{shown}: field 'trajopt.hips': '{hip}' is not a motor of "
                f"{description.robot}; allowed: {', '.join(sorted(joints))}"
            )


def _check_pd_gains(description: PairDescription, shown: Path | str) -> None:
    """Raises ConfigError: ``pd_gains`` names no gains file beside the baselines."""
    from ridempc.baselines.gains_files import gains_file_names

    named, files = description.pd_gains, gains_file_names()
    if named is not None and named not in files:
        raise ConfigError(
            f"{shown}: field 'pd_gains': '{named}' is not a gains file in ridempc/baselines/; "
            f"allowed: {', '.join(files)}"
        )
