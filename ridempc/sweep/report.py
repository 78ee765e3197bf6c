"""A sweep's report: ``report.md``, and ``report.html`` with its plots embedded as PNG.

Sections: survival per controller with its 95 % Wilson interval, the paired outcomes of
each pair of controllers, survival against each drawn quantity (binned, with the variants
per bin), the metrics' distributions per controller, and the worst rides with the
``ridempc sim`` command that replays each.
"""

from __future__ import annotations

import base64
import html
import io
import math
import shlex
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ridempc.io import atomic_write_text
from ridempc.sweep.aggregate import SWEEP_METRICS
from ridempc.sweep.stats import survived, wilson

__all__ = [
    "MAX_BINS",
    "WORST_RIDES",
    "replay_command",
    "survival_table",
    "sweep_command",
    "write_report",
]

MAX_BINS: int = 5  # bins per drawn quantity: 20 variants a bin at 100 samples
WORST_RIDES: int = 5  # worst rides listed per controller
EXTREME_DRAWS: int = 3  # draws named per worst ride: a table row one line wide


@dataclass
class _Section:
    title: str
    text: str = ""
    rows: list[list[str]] = field(default_factory=list)  # the first row is the header
    figure: bytes | None = None  # PNG
    commands: list[str] = field(default_factory=list)


def replay_command(
    results: Mapping[str, Any], variant: Mapping[str, Any], controller: str, folder: Path
) -> str:
    """The ``ridempc sim`` command that rides ``variant`` with ``controller`` again."""
    scenario = folder / variant["scenario_file"]
    out = folder / "replay" / f"{variant['id']}-{controller}"
    return shlex.join(
        [
            "ridempc",
            "sim",
            "--robot",
            results["robot"],
            "--board",
            results["board"],
            "--controller",
            controller,
            "--scenario",
            str(scenario),
            "--seed",
            str(variant["seed"]),
            "--out",
            str(out),
        ]
    )


def _markdown_table(rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(rows[0]) + " |", "|" + "---|" * len(rows[0])]
    lines += ["| " + " | ".join(r) + " |" for r in rows[1:]]
    return "\n".join(lines)


def survival_table(results: Mapping[str, Any]) -> str:
    """Survival per controller and the paired counts, as Markdown (also printed)."""
    rows = [
        ["controller", "survived", "rate", "95 % interval", "failed", "fallbacks", "worker memory"]
    ]
    for name, c in results["controllers"].items():
        low, high = c["survival_ci95"]
        memory = c["worker_peak_rss_mib"]
        # rides handed to a backup law (ridempc.mpc.handover), handovers in all, and the
        # survivals that ended on the backup (the backup's, not the controller's)
        handed = f"{c.get('fallback_rides', 0)} rides ({c.get('fallbacks', 0)})"
        if c.get("backup_survivals"):
            handed += f", {c['backup_survivals']} survived on it"
        rows.append(
            [
                name,
                f"{c['survived']}/{c['rides']}",
                f"{c['survival_rate']:.1%}",
                f"[{low:.1%}, {high:.1%}]",
                str(c["failed"]),
                handed,
                "-" if memory is None else f"{memory:.0f} MiB",
            ]
        )
    text = _markdown_table(rows)
    for pair in results["paired"]:
        a, b = pair["controllers"]
        text += "\n\n" + _markdown_table(
            [
                ["paired", f"{b} survived", f"{b} fell"],
                [f"{a} survived", str(pair["both_survived"]), str(pair[f"only_{a}_survived"])],
                [f"{a} fell", str(pair[f"only_{b}_survived"]), str(pair["neither_survived"])],
            ]
        )
        text += f"\n\nMcNemar exact p = {pair['mcnemar_p']:.3g} ({a} against {b})"
    return text


def _png(fig: Any) -> bytes:
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    try:
        fig.savefig(buffer, format="png", dpi=90)
    finally:
        plt.close(fig)
    return buffer.getvalue()


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _bar(rate: float, low: float, high: float) -> tuple[float, float]:
    """An interval as error-bar lengths below and above the rate; never negative (at 0 or
    n of n survivals, the bound and the rate differ in their last bits)."""
    return max(0.0, rate - low), max(0.0, high - rate)


def _survival_section(results: Mapping[str, Any]) -> _Section:
    plt = _pyplot()
    names = list(results["controllers"])
    rates = [results["controllers"][c]["survival_rate"] for c in names]
    bars = np.array(
        [
            _bar(r, *results["controllers"][c]["survival_ci95"])
            for c, r in zip(names, rates, strict=True)
        ]
    )
    fig, ax = plt.subplots(figsize=(1.6 + 1.2 * len(names), 3.2))
    ax.bar(names, rates, yerr=bars.T, capsize=6, color="tab:blue", alpha=0.7)
    ax.set_ylim(0.0, 1.05)
    ax.set_ylabel("survival [-]")
    ax.set_title("survival, 95 % Wilson interval")
    fig.tight_layout()
    return _Section("Survival", survival_table(results), figure=_png(fig))


def _bins(values: np.ndarray) -> list[tuple[float, float, np.ndarray]]:
    """Up to MAX_BINS equal-width bins over the values' range, each with its members."""
    low, high = float(values.min()), float(values.max())
    count = min(MAX_BINS, len(np.unique(values)))
    edges = np.linspace(low, high, count + 1)
    index = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, count - 1)
    return [(float(edges[i]), float(edges[i + 1]), index == i) for i in range(count)]


def _quantity_sections(results: Mapping[str, Any]) -> list[_Section]:
    variants = results["variants"]
    names = sorted({k for v in variants for k in v["drawn"]})
    controllers = list(results["controllers"])
    sections = []
    plt = _pyplot()
    for name in names:
        drawn = [v for v in variants if name in v["drawn"]]
        values = np.array([float(v["drawn"][name]) for v in drawn])
        if len(np.unique(values)) < 2:
            continue
        bins = _bins(values)
        rows = [[name, "variants", *controllers]]
        fig, ax = plt.subplots(figsize=(6.0, 3.0))
        width = bins[0][1] - bins[0][0]
        for j, c in enumerate(controllers):  # side by side within each bin
            dodge = width * 0.1 * (j - (len(controllers) - 1) / 2)
            kept = np.array([survived(v["summaries"][c]) for v in drawn])
            centres, rates, errors = [], [], []
            for low, high, members in bins:
                n, k = int(members.sum()), int(kept[members].sum())
                if n:
                    lo, hi = wilson(k, n)
                    centres.append(0.5 * (low + high) + dodge)
                    rates.append(k / n)
                    errors.append(_bar(k / n, lo, hi))
            ax.errorbar(centres, rates, yerr=np.array(errors).T, marker="o", capsize=4, label=c)
        for low, high, members in bins:
            n = int(members.sum())
            cells = []
            for c in controllers:
                k = sum(
                    survived(v["summaries"][c]) for v, m in zip(drawn, members, strict=True) if m
                )
                cells.append(f"{k}/{n}" if n else "-")
            rows.append([f"[{low:.4g}, {high:.4g}]", str(n), *cells])
            ax.annotate(f"n={n}", (0.5 * (low + high), 1.02), ha="center", fontsize=7)
        ax.set_ylim(-0.05, 1.1)
        ax.set_xlabel(name)
        ax.set_ylabel("survival [-]")
        ax.legend(fontsize=8, loc="lower left")
        ax.grid(alpha=0.3)
        fig.tight_layout()
        sections.append(_Section(f"Survival against {name}", rows=rows, figure=_png(fig)))
    return sections


def _metrics_section(results: Mapping[str, Any]) -> _Section | None:
    controllers = list(results["controllers"])
    spreads = {c: results["controllers"][c]["metrics"] for c in controllers}
    reported = [m for m in SWEEP_METRICS if any(spreads[c][m]["rides"] for c in controllers)]
    if not reported:
        return None
    rows = [["metric", *controllers]]
    for m in reported:
        cells = []
        for c in controllers:
            s = results["controllers"][c]["metrics"][m]
            cells.append(
                "-" if not s["rides"] else f"{s['median']:.4g} / {s['p90']:.4g} (n={s['rides']})"
            )
        rows.append([f"{m} [{SWEEP_METRICS[m]}] median / p90", *cells])
    plt = _pyplot()
    columns = min(3, len(reported))
    lines = math.ceil(len(reported) / columns)
    fig, axes = plt.subplots(lines, columns, figsize=(4.0 * columns, 2.8 * lines), squeeze=False)
    for ax, m in zip(axes.flat, reported, strict=False):
        data = [
            [
                float(v["summaries"][c][m])
                for v in results["variants"]
                if v["summaries"][c].get(m) is not None
            ]
            for c in controllers
        ]
        shown = [(c, d) for c, d in zip(controllers, data, strict=True) if d]
        ax.boxplot([d for _, d in shown])
        ax.set_xticks(range(1, len(shown) + 1), [c for c, _ in shown])
        ax.set_title(f"{m} [{SWEEP_METRICS[m]}]", fontsize=9)
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(reported) :]:
        ax.set_visible(False)
    fig.tight_layout()
    return _Section("Metrics per controller", rows=rows, figure=_png(fig))


def _badness(summary: Mapping[str, Any]) -> tuple[int, float, float]:
    """Sort key, worst first: failed, then fallen earliest, then the largest velocity error."""
    failed = summary.get("status") == "failed"
    fall = summary.get("fall_time_s")
    rmse = summary.get("velocity_rmse")
    return (
        0 if failed else 1 if summary.get("fell") else 2,
        float(fall) if fall is not None else math.inf,
        -float(rmse) if rmse is not None else 0.0,
    )


def _extreme_draws(variants: Sequence[Mapping[str, Any]]) -> dict[str, list[str]]:
    """Per variant, its ``EXTREME_DRAWS`` draws furthest into the tails of what the sweep
    drew (by rank among the variants), e.g. ``payload.fraction 0.29 (top 3 %)``: a hard
    distribution draws twenty quantities, and the ones at the edge of their range are the
    likely causes of a fall."""
    ranks: dict[str, dict[str, float]] = {v["id"]: {} for v in variants}
    for name in sorted({k for v in variants for k in v["drawn"]}):
        drawn = [v for v in variants if name in v["drawn"]]
        values = np.array([float(v["drawn"][name]) for v in drawn])
        if len(values) < 2 or np.ptp(values) == 0.0:
            continue
        order = (np.argsort(np.argsort(values)) + 0.5) / len(values)  # mid-rank in (0, 1)
        for v, rank in zip(drawn, order, strict=True):
            ranks[v["id"]][name] = float(rank)
    out = {}
    for v in variants:
        tails = sorted(ranks[v["id"]].items(), key=lambda kv: -abs(kv[1] - 0.5))
        out[v["id"]] = [
            f"{k} {float(v['drawn'][k]):.4g} "
            f"({'top' if r > 0.5 else 'bottom'} {100 * min(r, 1 - r):.0f} %)"
            for k, r in tails[:EXTREME_DRAWS]
        ]
    return out


def _worst_section(results: Mapping[str, Any], folder: Path) -> _Section:
    rows = [["controller", "variant", "seed", "outcome", "draws furthest in the tails"]]
    extremes = _extreme_draws(results["variants"])
    commands = []
    for c in results["controllers"]:
        ranked = sorted(results["variants"], key=lambda v: _badness(v["summaries"][c]))
        for v in ranked[:WORST_RIDES]:
            s = v["summaries"][c]
            if s.get("status") == "failed":
                outcome = f"failed: {s.get('error')}"
            elif s.get("fell"):
                outcome = f"fell at {s['fall_time_s']:.2f} s ({s.get('fall_reason')})"
            else:
                rmse = s.get("velocity_rmse")
                outcome = "rode" + ("" if rmse is None else f", velocity RMSE {rmse:.3g} m/s")
            drawn = ", ".join(extremes[v["id"]])
            rows.append([c, v["id"], str(v["seed"]), outcome, drawn or "-"])
            commands.append(f"# {c} {v['id']}: {outcome}")
            commands.append(replay_command(results, v, c, folder))
    text = (
        "Each ride again, with its log and plots: the commands below; every drawn value "
        "of a variant is in its `variants/<id>.toml`."
    )
    return _Section("Worst rides", text, rows=rows, commands=commands)


def _sections(results: Mapping[str, Any], folder: Path) -> list[_Section]:
    sections = [_survival_section(results), *_quantity_sections(results)]
    metrics = _metrics_section(results)
    if metrics is not None:
        sections.append(metrics)
    sections.append(_worst_section(results, folder))
    return sections


def _title(results: Mapping[str, Any]) -> str:
    return (
        f"Sweep: {results['robot']} / {results['board']} / {results['scenario']}, "
        f"distribution {results['distribution']}, {results['samples']} variants, "
        f"seed {results['seed']}"
    )


def sweep_command(results: Mapping[str, Any], folder: Path) -> str:
    """The ``ridempc sweep`` command that made (and resumes) this sweep."""
    controllers = ",".join(results["controllers"])
    words = ["ridempc", "sweep", "--robot", results["robot"], "--board", results["board"],
             "--scenario", results["scenario"], "--distribution", results["distribution"],
             "--samples", str(results["samples"]), "--controllers", controllers,
             "--seed", str(results["seed"])]  # fmt: skip
    if results.get("duration") is not None:
        words += ["--duration", f"{results['duration']:g}"]
    return shlex.join([*words, "--out", str(folder)])


def _markdown(results: Mapping[str, Any], sections: Sequence[_Section], folder: Path) -> str:
    command = sweep_command(results, folder)
    parts = [f"# {_title(results)}", f"```sh\n{command}\n```", "Plots: report.html."]
    for s in sections:
        parts.append(f"## {s.title}")
        if s.text:
            parts.append(s.text)
        if s.rows:
            parts.append(_markdown_table(s.rows))
        if s.commands:
            parts.append("```sh\n" + "\n".join(s.commands) + "\n```")
    return "\n\n".join(parts) + "\n"


def _html_table(rows: Sequence[Sequence[str]]) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in rows[0])
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows[1:]
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _html(results: Mapping[str, Any], sections: Sequence[_Section], folder: Path) -> str:
    title = html.escape(_title(results))
    parts = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>{title}</title><style>body{{font-family:sans-serif;max-width:70em;"
        "margin:auto}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;"
        "padding:2px 8px;text-align:right}pre{background:#f4f4f4;padding:.5em;"
        "overflow-x:auto}</style></head><body>",
        f"<h1>{title}</h1>",
        f"<pre>{html.escape(sweep_command(results, folder))}</pre>",
    ]
    for s in sections:
        parts.append(f"<h2>{html.escape(s.title)}</h2>")
        if s.figure is not None:
            data = base64.b64encode(s.figure).decode()
            parts.append(f"<img alt='{html.escape(s.title)}' src='data:image/png;base64,{data}'>")
        if s.text and not s.text.startswith("|"):
            parts.append(f"<p>{html.escape(s.text)}</p>")
        elif s.text:  # the survival tables
            for block in s.text.split("\n\n"):
                if block.startswith("|"):
                    lines = [ln for ln in block.splitlines() if not ln.startswith("|---")]
                    rows = [[c.strip() for c in ln.strip("|").split("|")] for ln in lines]
                    parts.append(_html_table(rows))
                else:
                    parts.append(f"<p>{html.escape(block)}</p>")
        if s.rows:
            parts.append(_html_table(s.rows))
        if s.commands:
            parts.append("<pre>" + html.escape("\n".join(s.commands)) + "</pre>")
    parts.append("</body></html>\n")
    return "\n".join(parts)


def write_report(results: Mapping[str, Any], folder: Path) -> None:
    """Write ``report.md`` and ``report.html`` into ``folder`` (atomically)."""
    sections = _sections(results, folder)
    atomic_write_text(folder / "report.md", _markdown(results, sections, folder))
    atomic_write_text(folder / "report.html", _html(results, sections, folder))
