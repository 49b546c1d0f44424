"""Chart primitives for the report's figures: grouped bars, lines, strips, cost bars.

Each function takes score rows and returns a `matplotlib.figure.Figure` (no pyplot, no
global state); `rover.report.figures` decides which figures a run gets and writes them.
Rows are grouped by `attr` ("variant" or "series", see `EpisodeScore`) and every group is
summarised as mean and standard error, the form of every figure in the paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from matplotlib.figure import Figure

from rover.eval.stratify import nonexpert_bin
from rover.report.scores import EpisodeScore, mean_se

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


def new_figure(width: float, height: float) -> Figure:
    # sized for a ~560 px wide slot on the page, so 9-10 pt text stays readable there
    return Figure(figsize=(width, height), layout="constrained")


def legend(fig: Figure, ax) -> None:
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


def bar_axes(ax, rows, metric, label, variants, colors, key, xlabel, attr="variant") -> None:
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
        _grouped_bars(ax, x, i, len(variants), width, means, ses, colors[v], v)
    ax.set_xticks(x, [str(g) for g in groups], rotation=20 if len(groups) > 4 else 0)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(label)
    ax.axhline(0, color="black", linewidth=0.6)
    ax.grid(axis="y", alpha=0.3)


def two_panel_bars(rows, metric, label, variants, colors) -> Figure:
    fig = new_figure(7.6, 3.3)
    axes = fig.subplots(1, 2, width_ratios=[3, 2])
    bar_axes(
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
    bar_axes(
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
    legend(fig, axes[0])
    return fig


def bars(rows, metric, label, variants, colors, key, xlabel, attr="variant") -> Figure:
    fig = new_figure(6.4, 3.2)
    ax = fig.subplots()
    bar_axes(ax, rows, metric, label, variants, colors, key, xlabel, attr)
    legend(fig, ax)
    return fig


def time_diff_hist(rows, variants, colors) -> Figure:
    """Per method: a histogram as a row of dots (one per question) over a box of quartiles.

    Overlaid histograms of eight methods hide each other; one row per method keeps every
    distribution visible and still reads like the paper's histogram (Fig. 6).
    """
    diffs_by = {v: [d for r in rows if r.series == v for d in r.qa_time_diffs] for v in variants}
    shown = [v for v in variants if diffs_by[v]]
    fig = new_figure(6.4, 0.9 + 0.42 * len(shown))
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


def non_expert_bin(r: EpisodeScore) -> str | None:
    return nonexpert_bin(r.non_expert_share)  # the same bins as metrics.json


def line_by(
    rows,
    variants,
    colors,
    metric: str,
    key: Callable,
    xlabel: str,
    ylabel: str,
    attr: str = "variant",
) -> Figure:
    fig = new_figure(6.4, 3.2)
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
    legend(fig, ax)
    return fig


def window_ablation(rows: list[EpisodeScore]) -> Figure:
    fig = new_figure(6.4, 3.0)
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


def cost_bars(rows, variants, colors) -> Figure:
    fig = new_figure(6.8, 3.3)
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
    legend(fig, ax)
    return fig


def _group_order(group: str) -> tuple[int, str]:
    """'0-10' < '10-20' < '20-30'; state types in the paper's order; others by name."""
    states = {"expert": 0, "interpolating": 1, "non_expert": 2}
    if group in states:
        return states[group], group
    head = group.split("-", 1)[0]
    return (int(head), group) if head.isdigit() else (10**6, group)


def strata_bars(agg: list[dict], label: str, variants: list[str], colors: dict[str, str]) -> Figure:
    """Two panels of precomputed means: (a) by frames in context, (b) by state type (App. H).

    `agg` rows: {"series", "by" ("context" | "state_type"), "group", "mean", "se"}.
    """
    fig = new_figure(7.6, 3.3)
    axes = fig.subplots(1, 2)
    for ax, by, xlabel in (
        (axes[0], "context", "(a) frames in context when predicted"),
        (axes[1], "state_type", "(b) state type at the frame"),
    ):
        rows = [a for a in agg if a["by"] == by]
        groups = sorted({a["group"] for a in rows}, key=_group_order)
        if not groups:
            ax.set_visible(False)
            continue
        shown = [v for v in variants if any(a["series"] == v for a in rows)]
        width = 0.8 / max(len(shown), 1)
        x = np.arange(len(groups))
        for i, v in enumerate(shown):
            cell = {a["group"]: a for a in rows if a["series"] == v}
            means = [cell[g]["mean"] if g in cell else np.nan for g in groups]
            ses = [
                cell[g]["se"] if g in cell and cell[g]["se"] is not None else np.nan for g in groups
            ]
            _grouped_bars(ax, x, i, len(shown), width, means, ses, colors[v], v)
        ax.set_xticks(x, [g.replace("_", "-") for g in groups])
        ax.set_xlabel(xlabel)
        ax.set_ylabel(label)
        ax.axhline(0, color="black", linewidth=0.6)
        ax.grid(axis="y", alpha=0.3)
    legend(fig, axes[0] if axes[0].get_visible() else axes[1])
    return fig


def _grouped_bars(ax, x, i: int, n: int, width: float, means, ses, color, label: str) -> None:
    """Series i of n side by side at each group position, with standard-error whiskers."""
    ax.bar(
        x + (i - (n - 1) / 2) * width,
        means,
        width,
        yerr=ses,
        color=color,
        label=label,
        capsize=2,
        error_kw={"elinewidth": 0.8},
    )
