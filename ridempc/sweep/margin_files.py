"""What ``ridempc margin`` writes into its ``--out`` folder, and the table it prints.

- ``rides/<direction>/<magnitude>.toml``: the scenario of every ride, so that any ride replays
  with ``ridempc sim --scenario`` and the search's seed;
- ``margin.png``: the margins on a polar plot, N/kg radially;
- ``margin.json``, last: the margins, every ride and how it ended. Its absence marks a
  search that did not finish.

Every file is written atomically. The files an earlier ``margin``, ``sim`` or ``compare``
wrote in the folder are removed before the first ride (margin.json first), so the folder
never mixes two runs; nothing else there is touched.
"""

from __future__ import annotations

import math
import shlex
from pathlib import Path
from typing import Any, cast

from ridempc.checks import writable_dir
from ridempc.errors import ConfigError
from ridempc.io import atomic_savefig, atomic_write_json, atomic_write_text
from ridempc.results import check_clearable, clear_results
from ridempc.sweep.bisection import Margin, Outcome
from ridempc.sweep.margin import MarginResult
from ridempc.sweep.pushes import PUSH_DURATION_S, direction_key

__all__ = [
    "MARGIN_FILES",
    "RIDES_DIR",
    "check_margin_out",
    "clear_margin",
    "margin_payload",
    "margin_table",
    "plot_margin",
    "ride_file",
    "write_margin",
]

MARGIN_FILES: tuple[str, ...] = ("margin.json", "margin.png")  # margin.json first: see clear
RIDES_DIR: str = "rides"
# The rider's own words for the principal directions on the plot.
_COMPASS: dict[int, str] = {0: "0° forward", 90: "90° left", 180: "180° back", 270: "270° right"}
_DPI: int = 120  # a 6-inch plot at 720 pixels: readable on a screen and in a report


def ride_file(degrees: float, magnitude: float) -> str:
    """Where a ride's scenario is written, relative to ``--out``; magnitude 0 is the
    unpushed ride."""
    if magnitude == 0.0:
        return f"{RIDES_DIR}/unpushed.toml"
    return f"{RIDES_DIR}/{direction_key(degrees)}/{magnitude:g}.toml"


def check_margin_out(out: Path) -> Path:
    """``out`` if the command can write its files there (before any ride).

    Raises:
        ConfigError: A folder that cannot be written or created, or a name the command
            writes taken by something it cannot replace.
    """
    out = writable_dir(out, "--out folder")
    check_clearable(out)
    for name in MARGIN_FILES:
        if (out / name).is_dir() and not (out / name).is_symlink():
            raise ConfigError(
                f"{out / name}: a folder where ridempc margin writes its file '{name}'; "
                "allowed: an --out folder without it"
            )
    rides = out / RIDES_DIR
    if rides.exists() and not rides.is_dir():
        raise ConfigError(
            f"{rides}: a file where ridempc margin writes its folder '{RIDES_DIR}'; "
            "allowed: an --out folder without it"
        )
    return out


def _unlink(path: Path) -> None:
    try:
        path.unlink(missing_ok=True)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot remove an earlier run's file ({exc})") from exc


def clear_margin(out: Path) -> None:
    """Remove what an earlier ``margin`` (and ``sim`` or ``compare``) wrote in ``out``:
    margin.json first, then the plot, the rides' scenario files and their temporary files,
    and the rides' folders left empty."""
    if not out.is_dir():
        return
    for name in MARGIN_FILES:
        for path in (out / name, *(p for p in out.glob(f".{name}.*") if p.is_file())):
            _unlink(path)
    clear_results(out)
    rides = out / RIDES_DIR
    if not rides.is_dir() or rides.is_symlink():
        return
    folders = [rides, *(p for p in rides.iterdir() if p.is_dir() and not p.is_symlink())]
    for folder in reversed(folders):
        for path in folder.glob("*.toml"):
            _unlink(path)
        for path in folder.glob(".*.toml.*"):  # a killed run's temporary files
            _unlink(path)
        try:
            folder.rmdir()
        except OSError:  # not empty: it holds files ridempc did not write
            pass


def _outcome(outcome: Outcome) -> dict[str, Any]:
    return {
        "survived": outcome.survived,
        "status": outcome.status,
        "fall_time_s": outcome.fall_time_s,
        "error": outcome.error,
    }


def margin_payload(result: MarginResult) -> dict[str, Any]:
    """``margin.json``: the margins [N/kg] by direction [deg], and every ride."""
    spec = result.spec
    search = spec.search
    keys = {degrees: direction_key(degrees) for degrees in result.margins}
    replay = " ".join(
        shlex.quote(part)
        for part in (
            "ridempc",
            "sim",
            "--robot",
            spec.robot,
            "--board",
            spec.board,
            "--controller",
            spec.controller,
        )
    )
    return {
        "robot": spec.robot,
        "board": spec.board,
        "controller": spec.controller,
        "scenario": spec.scenario.name,
        "seed": spec.seed,
        "push_duration_s": PUSH_DURATION_S,
        "push_time_s": spec.push_time,
        "duration_after_s": spec.duration_after,
        "tolerance": search.tolerance,
        "first_push": search.start,
        "max_push": search.cap,
        "checks": search.checks,
        "margins": {keys[d]: m.margin for d, m in result.margins.items()},
        "capped": {keys[d]: m.capped for d, m in result.margins.items()},
        "monotone": {keys[d]: m.monotone for d, m in result.margins.items()},
        "boundaries": {keys[d]: m.boundary for d, m in result.margins.items()},
        "lowest_falls": {keys[d]: m.lowest_fall for d, m in result.margins.items()},
        "failed_rides": result.failed,
        "rides_total": 1 + sum(len(m.trials) for m in result.margins.values()),
        "wall_time_s": round(result.wall_time_s, 1),
        "unpushed": {**_outcome(result.unpushed), "scenario_file": ride_file(0.0, 0.0)},
        "rides": {
            keys[d]: [
                {
                    "magnitude": t.magnitude,
                    "phase": t.phase,
                    **_outcome(t.outcome),
                    "scenario_file": ride_file(d, t.magnitude),
                }
                for t in m.trials
            ]
            for d, m in result.margins.items()
        },
        "replay": f"{replay} --scenario <out>/<scenario_file> --seed {spec.seed} --out <folder>",
    }


def _note(margin: Margin) -> str:
    notes = []
    if margin.capped:
        notes.append("no fall up to the cap")
    if not margin.monotone:
        notes.append(
            f"non-monotone: fell at {margin.lowest_fall:g}, survived up to {margin.boundary:g}"
        )
    if margin.failed:
        notes.append(f"{margin.failed} ride(s) failed")
    return "; ".join(notes)


def margin_table(result: MarginResult) -> str:
    """One line per direction: its margin [N/kg], its rides and what to know about them."""
    spec = result.spec
    lines = [
        f"{spec.robot}/{spec.board}/{spec.controller} '{spec.scenario.name}' seed {spec.seed}: "
        f"largest push survived, {PUSH_DURATION_S:g} s on the base at {spec.push_time:g} s "
        f"(tolerance {spec.search.tolerance:g} N/kg)",
        f"{'direction [deg]':>15}  {'margin [N/kg]':>13}  {'rides':>5}  note",
    ]
    for degrees, margin in result.margins.items():
        shown = f"{'>= ' if margin.capped else ''}{margin.margin:.2f}"
        lines.append(
            f"{direction_key(degrees):>15}  {shown:>13}  {len(margin.trials):>5}  {_note(margin)}"
        )
    if not result.unpushed.survived:
        how = result.unpushed.error or f"fell at {result.unpushed.fall_time_s} s"
        lines.append(f"without a push the ride does not survive either ({how})")
    return "\n".join(lines)


def plot_margin(result: MarginResult, path: Path) -> None:
    """The margins on a polar plot [N/kg], 0° forward, counter-clockwise."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.projections.polar import PolarAxes

    spec = result.spec
    angles = [math.radians(d) for d in result.margins]
    values = [m.margin for m in result.margins.values()]
    fig = plt.figure(figsize=(6, 6))
    ax = cast(PolarAxes, fig.add_subplot(projection="polar"))
    ax.plot([*angles, angles[0]], [*values, values[0]], "o-", color="tab:blue")
    odd = [
        (a, m.margin)
        for a, m in zip(angles, result.margins.values(), strict=True)
        if m.capped or not m.monotone
    ]
    if odd:
        ax.plot(
            *zip(*odd, strict=True),
            "s",
            color="tab:red",
            mfc="none",
            ms=10,
            label="capped or non-monotone",
        )
        ax.legend(loc="lower right", fontsize=8)
    ax.set_theta_zero_location("E")  # 0°: forward, the rider's +x
    ax.set_theta_direction(1)
    ax.set_rlim(0.0, max(max(values), spec.search.tolerance) * 1.15)
    ax.set_xticks([math.radians(d) for d in range(0, 360, 45)])
    ax.set_xticklabels([_COMPASS.get(d, f"{d}°") for d in range(0, 360, 45)])
    ax.set_rlabel_position(22.5)  # the radial scale [N/kg] between the first two directions
    ax.set_title(
        f"{spec.robot} / {spec.board} / {spec.controller}: largest push survived [N/kg]\n"
        f"'{spec.scenario.name}', {PUSH_DURATION_S:g} s on the base, seed {spec.seed}",
        fontsize=10,
    )
    fig.tight_layout()
    try:
        atomic_savefig(fig, path, _DPI)
    finally:
        plt.close(fig)


def write_margin(out: Path, result: MarginResult) -> None:
    """Write the rides' scenarios, the plot and, last, ``margin.json`` into ``out``."""
    from ridempc.sweep.variants import scenario_toml

    spec = result.spec
    atomic_write_text(out / ride_file(0.0, 0.0), scenario_toml(spec.pushed(0.0, 0.0)))
    for degrees, margin in result.margins.items():
        for trial in margin.trials:
            scenario = spec.pushed(degrees, trial.magnitude)
            atomic_write_text(out / ride_file(degrees, trial.magnitude), scenario_toml(scenario))
    plot_margin(result, out / "margin.png")
    atomic_write_json(out / "margin.json", margin_payload(result))
