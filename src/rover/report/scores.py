"""Per-video scores for the figures, read from metrics.json's per-trace rows.

Nothing is scored here: each `EpisodeScore` is one `per_trace` row of the run's
metrics.json (written by `rover.eval.results.compute_metrics`, the one scorer), renamed
for drawing. Rates are percentages, as everywhere in rover.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from rover.eval.aggregate import mean_se as _eval_mean_se
from rover.report.run import RunData, TraceEntry


@dataclass
class EpisodeScore:
    """Every number the report shows about one trace (one configuration on one episode)."""

    variant: str  # display label of the configuration
    variant_id: str
    series: str  # the label without frame count
    method: str
    episode_id: str
    task: str
    task_group: str
    level: int | None
    num_frames: int
    view: str | None
    window: int | None
    tokens: int
    calls: int
    dataset: str | None = None
    setting_view: str | None = None  # the variant's view setting (None: each video's own)
    setting_frames: int | None = None  # the variant's frame-count setting (None: all)
    pearson: float | None = None
    l2: float | None = None
    voc: float | None = None
    frame_corr: float | None = None
    non_expert_share: float | None = None
    error_rate: float | None = None  # % of judged frames with a verifiably false statement
    success_rate: float | None = None
    qa_accuracy: float | None = None
    qa_precision: float | None = None
    qa_recall: float | None = None
    qa_time_diffs: list[int] = field(default_factory=list)  # stated - actual, in frames


def score_run(run: RunData) -> list[EpisodeScore]:
    """The per-video rows of every drawn trace, in the paper's method order."""
    return [score_entry(e) for e in run.entries]


def score_entry(entry: TraceEntry) -> EpisodeScore:
    r = entry.row
    return EpisodeScore(
        variant=entry.label,
        variant_id=entry.variant_id,
        series=entry.series,
        method=r["method"],
        episode_id=r["episode_id"],
        task=r.get("task") or entry.trace.task,
        task_group=r.get("task_group") or "all",
        level=r.get("level"),
        num_frames=int(r.get("n_frames") or entry.trace.num_frames),
        view=entry.view or None,
        window=r.get("window"),
        tokens=int(r.get("total_tokens") or 0),
        calls=int(r.get("calls") or 0),
        dataset=r.get("dataset"),
        setting_view=entry.setting_view,
        setting_frames=entry.setting_frames,
        pearson=_finite(r.get("pearson")),
        l2=_finite(r.get("l2")),
        voc=_finite(r.get("voc")),
        frame_corr=_finite(r.get("frame_corr")),
        non_expert_share=_finite(r.get("nonexpert_share")),
        error_rate=_finite(r.get("error_rate")),
        success_rate=_finite(r.get("success_rate")),
        qa_accuracy=_finite(r.get("qa_accuracy")),
        qa_precision=_finite(r.get("qa_precision")),
        qa_recall=_finite(r.get("qa_recall")),
        qa_time_diffs=list(r.get("qa_dts") or []),
    )


def mean_se(values: list[float | None]) -> tuple[float, float, int]:
    """Mean, standard error (NaN below two values) and count of the finite values."""
    return _eval_mean_se(values)


def variants_in_order(rows: list[EpisodeScore], attr: str = "variant") -> list[str]:
    seen: list[str] = []
    for r in rows:
        name = getattr(r, attr)
        if name not in seen:
            seen.append(name)
    return seen


def _finite(x: float | None) -> float | None:
    return None if x is None or math.isnan(x) or math.isinf(x) else float(x)
