"""The paper's kinds of figures (Sec. 5, App. A, F, H, I, J, M), drawn with matplotlib.

Figures are built on `matplotlib.figure.Figure` directly (the Agg canvas, no pyplot and no
global backend state), and each is written as PNG and SVG. A figure is drawn only when the
run holds the data it needs (verdicts for error rates, several window sizes for the window
ablation...), so a small run yields a short, honest report rather than empty axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from matplotlib import rc_context
from matplotlib.figure import Figure

from rover.methods.info import method_info
from rover.report import charts
from rover.report.charts import PALETTE
from rover.report.scores import EpisodeScore, variants_in_order

ORACLE_NOTE = "ORACLE OUTPUT: answers come from simulator ground truth, not a VLM"


@dataclass
class FigureFile:
    """One written figure: its stem, what it shows, and its files relative to the report."""

    name: str
    title: str
    caption: str
    png: str
    svg: str


# metric attribute -> (axis label, figure title, caption)
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


# frame-level strata read from metrics.json: metric -> (table, axis label, scale, title)
STRATA: dict[str, tuple[str, str, float, str]] = {
    "pearson": (
        "progress",
        "Pearson r with ground truth",
        1.0,
        "Progress by context length and state type",
    ),
    "error_rate": (
        "reasoning",
        "Reasoning error rate (%)",
        1.0,  # metrics.json rates are percentages already
        "Frame reasoning by context length and state type",
    ),
}


def variant_colors(rows: list[EpisodeScore]) -> dict[str, str]:
    """One fixed colour per configuration and per series, shared by tables, figures and
    viewer: a method's registry colour for its first configuration, spare colours after."""
    colors: dict[str, str] = {}
    used: set[str] = set()

    def pick(preferred: str) -> str:
        if preferred not in used:
            return preferred
        return next((c for c in PALETTE if c not in used), preferred)

    for r in rows:
        if r.series not in colors:
            colors[r.series] = pick(method_info(r.method).color)
            used.add(colors[r.series])
        if r.variant not in colors:
            same = [k for k, c in colors.items() if c == colors[r.series] and k != r.series]
            colors[r.variant] = colors[r.series] if not same else pick(colors[r.series])
            used.add(colors[r.variant])
    return colors


def write_figures(
    rows: list[EpisodeScore], out: Path, oracle: bool, aggregates: list[dict] | None = None
) -> list[FigureFile]:
    """Draw every figure the rows support into `out` (PNG + SVG); return what was written.

    `aggregates` are metrics.json's long-form rows; they supply the frame-level strata
    (context length, state type) that per-trace rows cannot.
    """
    with rc_context(_STYLE):
        return _write_figures(rows, out, oracle, aggregates or [])


_STYLE = {
    "font.size": 9,
    "axes.labelsize": 9,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "svg.hashsalt": "rover",  # stable ids: the same run gives the same SVG bytes
}


def _write_figures(
    rows: list[EpisodeScore], out: Path, oracle: bool, aggregates: list[dict]
) -> list[FigureFile]:
    out.mkdir(parents=True, exist_ok=True)
    colors = variant_colors(rows)
    written: list[FigureFile] = []
    # The paper's main figures compare methods at one setting; sweeps get their own figures.
    frames0, view0 = _primary_setting(rows)
    at_view = [r for r in rows if r.setting_view == view0]
    at_frames = [r for r in rows if r.setting_frames == frames0]
    main = [r for r in at_frames if r.setting_view == view0]
    series = variants_in_order(main, "series")
    note = ""
    if len(main) < len(rows):
        note = (
            f" Shown at {frames0 or 'all'} frames per video, view {view0 or 'own'}; other "
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
        fig = charts.two_panel_bars(main, metric, label, series, colors)
        save(fig, f"{metric}_by_group_level", title, caption + note)

    series_of = {r.variant_id: r.series for r in main}
    for metric, (table, label, scale, title) in STRATA.items():
        agg = [
            {
                "series": series_of[a["variant"]],
                "by": a["by"],
                "group": str(a["group"]),
                "mean": a["mean"] * scale,
                "se": None if a.get("se") is None else a["se"] * scale,
            }
            for a in aggregates
            if a.get("table") == table
            and a.get("metric") == metric
            and a.get("by") in ("context", "state_type")
            and a.get("variant") in series_of
            and isinstance(a.get("mean"), int | float)
        ]
        if agg:
            save(
                charts.strata_bars(agg, label, series, colors),
                f"{metric}_by_context_state",
                title,
                "Mean and standard error over videos, per frame stratum: how many "
                "frames the method had in context when it predicted a frame, and the state "
                "type at that frame (App. H). From metrics.json." + note,
            )

    if any(r.qa_time_diffs for r in main):
        save(
            charts.time_diff_hist(main, series, colors),
            "qa_temporal_distance",
            "Video QA: temporal distance (Fig. 6)",
            "Frames between when a method's descriptions say an event happened and when it "
            "did (negative: stated too early). Only questions answered yes correctly." + note,
        )
    if any(r.non_expert_share is not None for r in main):
        save(
            charts.line_by(
                main,
                series,
                colors,
                "frame_corr",
                charts.non_expert_bin,
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
    if len({r.setting_frames for r in at_view}) > 1 and any(r.pearson is not None for r in at_view):
        save(
            charts.line_by(
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
            "Robustness to frame count (App. I)",
            "Mean and standard error of the correlation with ground truth as the same videos "
            "are sampled with more frames (App. I).",
        )
    swept_views = len({r.setting_view for r in at_frames}) > 1
    if swept_views and any(r.pearson is not None for r in at_frames):
        fig = charts.bars(
            at_frames,
            "pearson",
            "Pearson r with ground truth",
            variants_in_order(at_frames, "series"),
            colors,
            lambda r: r.setting_view or "own",
            "Camera view",
            attr="series",
        )
        save(
            fig,
            "pearson_by_view",
            "Robustness to camera view (App. J)",
            "Mean and standard error of the correlation with ground truth by camera view.",
        )
    window_rows = [r for r in main if r.method == "rover" and r.window]
    if len({r.window for r in window_rows}) > 1 and any(r.pearson is not None for r in window_rows):
        save(
            charts.window_ablation(window_rows),
            "window_ablation",
            "Ablation: window size",
            "Correlation with ground truth of ROVER as its sliding window grows (App. M).",
        )
    if any(r.tokens for r in rows):
        save(
            charts.cost_bars(at_view, variants_in_order(at_view, "series"), colors),
            "cost_tokens",
            "Inference cost (App. F)",
            "Mean tokens per video (bars, left) and VLM calls per video (labels), by "
            "method and frame count (App. F).",
        )
    return written


def _primary_setting(rows: list[EpisodeScore]) -> tuple[int | None, str | None]:
    """The frame count and view most traces share (ties: more frames, first view)."""
    frames = [r.setting_frames for r in rows]
    frames0 = max(set(frames), key=lambda n: (frames.count(n), n or 10**9))
    views = [r.setting_view for r in rows if r.setting_frames == frames0]
    order = list(dict.fromkeys(views))
    view0 = max(order, key=lambda v: (views.count(v), -order.index(v)))
    return frames0, view0


def _metadata(ext: str) -> dict[str, str | None]:
    # keep files reproducible: no creation dates in them
    return {"Date": None} if ext == "svg" else {}
