"""A sweep checked and planned before anything rides: its names, scenario, distribution,
folder and engine checked, its variants drawn, and one :class:`~ridempc.sweep.runner.RideTask`
per variant and controller."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from ridempc.checks import writable_dir
from ridempc.errors import ConfigError, UnknownNameError
from ridempc.sweep.layout import SweepLayout, SweepManifest, digest
from ridempc.sweep.runner import RideTask

__all__ = ["MAX_SAMPLES", "SweepPlan", "parse_controllers", "plan_sweep"]

# Ten thousand variants of two controllers is days of wall time on a workstation: more is
# a typo, and a cluster user splits it into seeds.
MAX_SAMPLES: int = 10_000


def parse_controllers(text: str) -> list[str]:
    """``"pd,mpc"`` -> ``["pd", "mpc"]``, each a registered controller, none twice.

    Raises:
        ConfigError: Empty, or a controller named twice.
        UnknownNameError: A controller that does not exist.
    """
    from ridempc.controllers import controller_names

    names = [c.strip() for c in text.split(",") if c.strip()]
    if not names:
        raise ConfigError(f"--controllers {text!r}: allowed: comma-separated controller names")
    if len(set(names)) != len(names):
        raise ConfigError(f"--controllers {text}: names a controller twice")
    for name in names:
        if name not in controller_names():
            raise UnknownNameError("controller", name, controller_names())
    return names


@dataclass(frozen=True)
class SweepPlan:
    """A checked sweep, ready to ride.

    Attributes:
        layout: Its folder.
        manifest: What defines its rides.
        variants: Per variant its ``id``, ``seed``, ``drawn`` quantities and ``scenario_file``
            (relative to the folder), and its scenario file's text (``toml``).
        tasks: One ride per variant and controller, variant order.
    """

    layout: SweepLayout
    manifest: SweepManifest
    variants: tuple[dict[str, Any], ...]
    tasks: tuple[RideTask, ...]

    def header(self) -> dict[str, Any]:
        """What the sweep was, for ``sweep.json``."""
        m = self.manifest
        return {
            "robot": m.robot,
            "board": m.board,
            "scenario": m.scenario,
            "distribution": m.distribution,
            "seed": m.seed,
            "duration": m.duration,
        }

    def records(self) -> list[dict[str, Any]]:
        """The variants without their files' text."""
        return [{k: v for k, v in r.items() if k != "toml"} for r in self.variants]


def _with_duration(scenario: Any, duration: float | None) -> Any:
    if duration is None:
        return scenario
    try:  # checked again: a shorter ride may end before one of its events
        return type(scenario).model_validate({**scenario.model_dump(), "duration": duration})
    except ValidationError as exc:
        raise ConfigError.from_validation(f"--duration {duration:g}", exc) from exc


def plan_sweep(
    robot: str,
    board: str,
    scenario: str,
    distribution: str,
    samples: int,
    controllers: list[str],
    seed: int,
    out: Path,
    duration: float | None = None,
) -> SweepPlan:
    """Check everything and draw the variants; nothing is written or ridden.

    Raises:
        ConfigError: A bad number, an unwritable or foreign ``out``, a distribution or
            scenario that does not apply, a controller that does not ride the pair.
        UnknownNameError: A name that does not exist.
    """
    from ridempc.run import RideRequest, check_request
    from ridempc.scenarios import resolve_scenario
    from ridempc.sweep.distribution import load_distribution
    from ridempc.sweep.variants import draw_variants, scenario_toml

    out = writable_dir(Path(out), "--out folder")
    if not 1 <= samples <= MAX_SAMPLES:
        raise ConfigError(f"--samples {samples}: allowed: a whole number in [1, {MAX_SAMPLES}]")
    base = _with_duration(resolve_scenario(scenario, board), duration)
    drawn_from = load_distribution(distribution, board)  # the files first, then the scenes
    for controller in controllers:  # the pair, the scenario and the controllers, as sim does
        check_request(
            RideRequest(robot, board, controller, scenario, out=out, duration=duration, plots=False)
        )
    manifest = SweepManifest(
        robot=robot,
        board=board,
        scenario=scenario,
        scenario_sha256=digest(base),
        distribution=distribution,
        distribution_sha256=digest(drawn_from),
        controllers=tuple(controllers),
        seed=seed,
        duration=duration,
    )
    layout = SweepLayout(out)
    layout.check(manifest)
    drawn = draw_variants(base, drawn_from, robot=robot, board=board, samples=samples, seed=seed)
    variants = []
    tasks = []
    for variant in drawn:
        variants.append(
            {
                "id": variant.id,
                "seed": variant.seed,
                "drawn": dict(variant.drawn),
                "scenario_file": f"variants/{variant.id}.toml",
                "toml": scenario_toml(variant.scenario),
            }
        )
        for controller in controllers:
            tasks.append(
                RideTask(
                    variant=variant.id,
                    controller=controller,
                    robot=robot,
                    board=board,
                    scenario=variant.scenario,
                    seed=variant.seed,
                    summary_path=layout.ride_file(variant.id, controller),
                )
            )
    return SweepPlan(layout, manifest, tuple(variants), tuple(tasks))
