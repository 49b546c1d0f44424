"""The paper's kinds of figures (Sec. 5, App. A, F, H, I, M), drawn with matplotlib.

Figures are built on `matplotlib.figure.Figure` directly (the Agg canvas, no pyplot and no
global backend state), and each is written as PNG and SVG. A figure is drawn only when the
run holds the data it needs (verdicts for error rates, several window sizes for the window
ablation...), so a small run yields a short, honest report rather than empty axes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib import rc_context
from matplotlib.figure import Figure

from rover.eval.stratify import nonexpert_bin
from rover.report.scores import EpisodeScore, mean_se, variants_in_order

PALETTE = [
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#ff7f0e",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
    "#393b79",
    "#e7969c",
    "#637939",
    "#ffbb78",
    "#c5b0d5",
    "#8c6d31",
]
ORACLE_NOTE = "ORACLE OUTPUT: answers come from simulator ground truth, not a VLM"


@dataclass
class FigureFile:
    """One written figure: its stem, what it shows, and its files relative to the report."""

    name: str
    title: str
    caption: str
    png: str
    svg: str


# metric attribute -> (axis label, figure title, caption, higher is better)
METRICS: dict[str, tuple[str, str, str]] = {
    "pearson": (
        "Pearson r with ground truth",
        "Progress: correlation with ground truth",
        "Mean and standard error of the Pearson correlation between predicted and "
        "ground-truth progress, by task group (a) and trajectory level (b).",
    ),
    "l2": (
        "L2 distance to ground truth",
        "Progress: distance to ground truth",
        "Mean and standard error of the L2 distance between predicted and ground-truth "
        "progress (both 0-100), by task group (a) and trajectory level (b). Lower is better.",
    ),
    "voc": (
        "VOC (Spearman r with frame order)",
        "Progress: value-order correlation",
        "Mean and standard error of VOC, the rank correlation of predictions with frame order.",
    ),
    "error_rate": (
        "Reasoning error rate (%)",
        "Frame reasoning: error rate",
        "Mean and standard error of the percentage of frames whose description states "
        "something verifiably false, by task group (a) and trajectory level (b).",
    ),
    "success_rate": (
        "Reasoning success rate (%)",
        "Frame reasoning: success rate",
        "Mean and standard error of the percentage of frames whose description states "
        "something verifiably true and nothing false.",
    ),
    "qa_accuracy": (
        "Video QA accuracy (%)",
        "Video QA: accuracy",
        "Percentage of questions where the method's descriptions lead to the right yes/no.",
    ),
    "qa_precision": (
        "Video QA precision (%)",
        "Video QA: precision",
        "Percentage of predicted occurrences that actually occurred.",
    ),
    "qa_recall": (
        "Video QA recall (%)",
        "Video QA: recall",
        "Percentage of actual occurrences the method's descriptions identified.",
    ),
}


def variant_colors(rows: list[EpisodeScore]) -> dict[str, str]:
    """One fixed colour per configuration (and per series), shared by figures and viewer."""
    colors = {v: PALETTE[i % len(PALETTE)] for i, v in enumerate(variants_in_order(rows))}
    for i, name in enumerate(variants_in_order(rows, "series")):
        colors.setdefault(name, PALETTE[i % len(PALETTE)])
    return colors


def write_figures(rows: list[EpisodeScore], out: Path, oracle: bool) -> list[FigureFile]:
    """Draw every figure the rows support into `out` (PNG + SVG); return what was written."""
    with rc_context(_STYLE):
        return _write_figures(rows, out, oracle)


_STYLE = {
    "font.size": 9,
    "axes.labelsize": 9,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "svg.hashsalt": "rover",  # stable ids: the same run gives the same SVG bytes
}


def _write_figures(rows: list[EpisodeScore], out: Path, oracle: bool) -> list[FigureFile]:
    out.mkdir(parents=True, exist_ok=True)
    colors = variant_colors(rows)
    written: list[FigureFile] = []
    # The paper's main figures compare methods at one setting; sweeps get their own figures.
    frames0, view0 = _primary_setting(rows)
    at_view = [r for r in rows if r.view == view0]
    at_frames = [r for r in rows if r.num_frames == frames0]
    main = [r for r in at_frames if r.view == view0]
    series = variants_in_order(main, "series")
    note = ""
    if len(main) < len(rows):
        note = (
            f" Shown at {frames0} frames per video, view {view0 or 'default'}; other "
            "settings are in the sweep figures and the summary table."
        )

    def save(fig: Figure, name: str, title: str, caption: str) -> None:
        if oracle:  # a suptitle gets its own room in the constrained layout
            fig.suptitle(ORACLE_NOTE, color="#b00020", fontsize=9, fontweight="bold")
        for ext in ("png", "svg"):
            fig.savefig(out / f"{name}.{ext}", dpi=110, metadata=_metadata(ext))
        written.append(
            FigureFile(name, title, caption, f"{out.name}/{name}.png", f"{out.name}/{name}.svg")
        )

    for metric, (label, title, caption) in METRICS.items():
        if not any(getattr(r, metric) is not None for r in main):
            continue
        fig = _two_panel_bars(main, metric, label, series, colors)
        save(fig, f"{metric}_by_group_level", title, caption + note)

    if any(r.qa_time_diffs for r in main):
        save(
            _time_diff_hist(main, series, colors),
            "qa_temporal_distance",
            "Video QA: temporal distance",
            "Frames between when a method's descriptions say an event happened and when it "
            "did (negative: stated too early). Only questions answered yes correctly." + note,
        )
    if any(r.non_expert_share is not None for r in main):
        save(
            _line_by(
                main,
                series,
                colors,
                "frame_corr",
                _non_expert_bin,
                "Share of non-expert frames",
                "Correlation with frame number",
                attr="series",
            ),
            "frame_corr_by_non_expert",
            "Progress: correlation with frame number",
            "Mean and standard error of the correlation between frame number and predicted "
            "progress, by the share of non-expert states in the video (App. A.1). Accurate "
            "reasoning should track frame number less as the share grows." + note,
        )
    if len({r.num_frames for r in at_view}) > 1 and any(r.pearson is not None for r in at_view):
        save(
            _line_by(
                at_view,
                variants_in_order(at_view, "series"),
                colors,
                "pearson",
                lambda r: r.num_frames,
                "Frames per video",
                "Pearson r with ground truth",
                attr="series",
            ),
            "pearson_by_frame_count",
            "Robustness to frame count",
            "Mean and standard error of the correlation with ground truth as the same videos "
            "are sampled with more frames (App. H).",
        )
    if len({r.view for r in at_frames}) > 1 and any(r.pearson is not None for r in at_frames):
        fig = _bars(
            at_frames,
            "pearson",
            "Pearson r with ground truth",
            variants_in_order(at_frames, "series"),
            colors,
            lambda r: r.view or "default",
            "Camera view",
            attr="series",
        )
        save(
            fig,
            "pearson_by_view",
            "Robustness to camera view",
            "Mean and standard error of the correlation with ground truth by camera view.",
        )
    window_rows = [r for r in main if r.method == "rover" and r.window]
    if len({r.window for r in window_rows}) > 1 and any(r.pearson is not None for r in window_rows):
        save(
            _window_ablation(window_rows),
            "window_ablation",
            "Ablation: window size",
            "Correlation with ground truth of ROVER as its sliding window grows (App. M).",
        )
    if any(r.tokens for r in rows):
        save(
            _cost_bars(at_view, variants_in_order(at_view, "series"), colors),
            "cost_tokens",
            "Inference cost",
            "Mean tokens per video (bars, left) and VLM calls per video (labels), by "
            "method and frame count (App. F).",
        )
    return written


def _primary_setting(rows: list[EpisodeScore]) -> tuple[int, str | None]:
    """The frame count and view most traces share (ties: more frames, first view)."""
    frames = [r.num_frames for r in rows]
    frames0 = max(set(frames), key=lambda n: (frames.count(n), n))
    views = [r.view for r in rows if r.num_frames == frames0]
    order = list(dict.fromkeys(views))
    view0 = max(order, key=lambda v: (views.count(v), -order.index(v)))
    return frames0, view0


def _metadata(ext: str) -> dict[str, str | None]:
    # keep files reproducible: no creation dates in them
    return {"Date": None} if ext == "svg" else {}


def _new_figure(width: float, height: float) -> Figure:
    # sized for a ~560 px wide slot on the page, so 9-10 pt text stays readable there
    return Figure(figsize=(width, height), layout="constrained")


def _legend(fig: Figure, ax) -> None:
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        width_chars = fig.get_figwidth() * 13  # ~characters of 8 pt text per inch
        per_col = max(len(x) for x in labels) + 5
        fig.legend(
            handles,
            labels,
            loc="outside lower center",
            ncols=max(1, min(len(labels), 4, int(width_chars // per_col))),
            fontsize=8,
            frameon=False,
        )


def _bar_axes(ax, rows, metric, label, variants, colors, key, xlabel, attr="variant") -> None:
    groups = sorted({key(r) for r in rows if getattr(r, metric) is not None}, key=str)
    if not groups:
        ax.set_visible(False)
        return
    width = 0.8 / max(len(variants), 1)
    x = np.arange(len(groups))
    for i, v in enumerate(variants):
        stats_ = [
            mean_se([getattr(r, metric) for r in rows if getattr(r, attr) == v and key(r) == g])
            for g in groups
        ]
        means = [s[0] for s in stats_]
        ses = [s[1] for s in stats_]
        ax.bar(
            x + (i - (len(variants) - 1) / 2) * width,
            means,
            width,
            yerr=ses,
            color=colors[v],
            label=v,
            capsize=2,
            error_kw={"elinewidth": 0.8},
        )
    ax.set_xticks(x, [str(g) for g in groups], rotation=20 if len(groups) > 4 else 0)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(label)
    ax.axhline(0, color="black", linewidth=0.6)
    ax.grid(axis="y", alpha=0.3)


def _two_panel_bars(rows, metric, label, variants, colors) -> Figure:
    fig = _new_figure(7.6, 3.3)
    axes = fig.subplots(1, 2, width_ratios=[3, 2])
    _bar_axes(
        axes[0],
        rows,
        metric,
        label,
        variants,
        colors,
        lambda r: r.task_group,
        "(a) task group",
        "series",
    )
    has_levels = any(r.level is not None for r in rows)
    _bar_axes(
        axes[1],
        rows,
        metric,
        label,
        variants,
        colors,
        (lambda r: f"level {r.level}" if r.level is not None else "n/a"),
        "(b) trajectory level" if has_levels else "(b) level unknown",
        "series",
    )
    _legend(fig, axes[0])
    return fig


def _bars(rows, metric, label, variants, colors, key, xlabel, attr="variant") -> Figure:
    fig = _new_figure(6.4, 3.2)
    ax = fig.subplots()
    _bar_axes(ax, rows, metric, label, variants, colors, key, xlabel, attr)
    _legend(fig, ax)
    return fig


def _time_diff_hist(rows, variants, colors) -> Figure:
    """Per method: a histogram as a row of dots (one per question) over a box of quartiles.

    Overlaid histograms of eight methods hide each other; one row per method keeps every
    distribution visible and still reads like the paper's histogram (App. A, Fig. 3).
    """
    diffs_by = {v: [d for r in rows if r.series == v for d in r.qa_time_diffs] for v in variants}
    shown = [v for v in variants if diffs_by[v]]
    fig = _new_figure(6.4, 0.9 + 0.42 * len(shown))
    ax = fig.subplots()
    rng = np.random.default_rng(0)  # jitter only spreads overlapping dots; fixed for stability
    for i, v in enumerate(shown):
        ds = np.asarray(diffs_by[v], dtype=float)
        y = len(shown) - 1 - i
        q1, med, q3 = np.percentile(ds, [25, 50, 75])
        ax.barh(
            y,
            max(q3 - q1, 0.2),
            left=q1 if q3 > q1 else q1 - 0.1,
            height=0.6,
            color=colors[v],
            alpha=0.25,
            edgecolor=colors[v],
        )
        ax.vlines(med, y - 0.3, y + 0.3, color="black", linewidth=1.2)
        ax.scatter(
            ds + rng.uniform(-0.15, 0.15, len(ds)),
            y + rng.uniform(-0.22, 0.22, len(ds)),
            s=10,
            color=colors[v],
            alpha=0.7,
            zorder=3,
        )
    ax.set_yticks(range(len(shown)), list(reversed(shown)))
    ax.axvline(0, color="black", linewidth=0.8, linestyle="--")
    ax.set_xlabel("Stated frame - actual frame (negative: stated too early)")
    ax.grid(axis="x", alpha=0.3)
    return fig


def _non_expert_bin(r: EpisodeScore) -> str | None:
    return nonexpert_bin(r.non_expert_share)  # the same bins as metrics.json


def _line_by(
    rows,
    variants,
    colors,
    metric: str,
    key: Callable,
    xlabel: str,
    ylabel: str,
    attr: str = "variant",
) -> Figure:
    fig = _new_figure(6.4, 3.2)
    ax = fig.subplots()
    xs = sorted({key(r) for r in rows if key(r) is not None})
    for v in variants:
        pts = [
            (
                x,
                *mean_se(
                    [getattr(r, metric) for r in rows if getattr(r, attr) == v and key(r) == x]
                ),
            )
            for x in xs
        ]
        pts = [p for p in pts if p[3] > 0]
        if pts:
            px, m, se, _ = zip(*pts, strict=True)
            ax.errorbar(px, m, yerr=se, marker="o", color=colors[v], label=v, capsize=3)
    if xs and all(isinstance(x, int) for x in xs):
        ax.set_xticks(xs)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    _legend(fig, ax)
    return fig


def _window_ablation(rows: list[EpisodeScore]) -> Figure:
    fig = _new_figure(6.4, 3.0)
    ax = fig.subplots()
    windows = sorted({r.window for r in rows if r.window})
    stats_ = [mean_se([r.pearson for r in rows if r.window == w]) for w in windows]
    ax.errorbar(
        windows,
        [s[0] for s in stats_],
        yerr=[s[1] for s in stats_],
        marker="o",
        color=PALETTE[0],
        capsize=3,
    )
    ax.set_xticks(windows)
    ax.set_xlabel("Sliding window (frames)")
    ax.set_ylabel("Pearson r with ground truth")
    ax.grid(alpha=0.3)
    return fig


def _cost_bars(rows, variants, colors) -> Figure:
    fig = _new_figure(6.8, 3.3)
    ax = fig.subplots()
    counts = sorted({r.num_frames for r in rows})
    width = 0.8 / max(len(variants), 1)
    x = np.arange(len(counts))
    for i, v in enumerate(variants):
        toks = [
            mean_se([r.tokens for r in rows if r.series == v and r.num_frames == n]) for n in counts
        ]
        calls = [
            mean_se([r.calls for r in rows if r.series == v and r.num_frames == n])[0]
            for n in counts
        ]
        pos = x + (i - (len(variants) - 1) / 2) * width
        bars = ax.bar(pos, [t[0] for t in toks], width, color=colors[v], label=v)
        ax.bar_label(
            bars, [f"{c:.0f}" if not math.isnan(c) else "" for c in calls], fontsize=6, padding=1
        )
    ax.set_xticks(x, [f"{n} frames" for n in counts])
    ax.set_ylabel("Tokens per video (bar labels: calls)")
    ax.grid(axis="y", alpha=0.3)
    _legend(fig, ax)
    return fig
