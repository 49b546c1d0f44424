"""Per-episode scores for every trace, and their means with standard errors.

Task 1 numbers come from `rover.eval.progress_metrics` (the same functions `rover eval`
uses, so the page agrees with `metrics.json`): predictions and truth on 0..100, aligned by
original frame index. Task 2 and 3 numbers are computed from the run's judgement and QA
files; token and call counts from the trace itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from rover.eval.aggregate import mean_se as _eval_mean_se
from rover.eval.progress_metrics import score_progress
from rover.eval.stratify import nonexpert_share
from rover.report.run import RunData, TraceEntry


@dataclass
class EpisodeScore:
    """Every number the report shows about one trace (one configuration on one episode)."""

    variant: str  # display label of the configuration
    variant_id: str  # the run's variant id (file stem of the trace)
    series: str  # the label without frame count / view
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
    pearson: float | None = None
    l2: float | None = None
    voc: float | None = None
    frame_corr: float | None = None
    non_expert_share: float | None = None
    error_rate: float | None = None  # % of judged frames with a verifiably false statement
    success_rate: float | None = None  # % of frames true and not false
    qa_accuracy: float | None = None
    qa_precision: float | None = None
    qa_recall: float | None = None
    qa_time_diffs: list[int] = field(default_factory=list)  # stated - actual, in frames


def score_run(run: RunData) -> list[EpisodeScore]:
    """Score every trace of the run, in the paper's method order."""
    return [score_entry(run, e) for e in run.entries]


def score_entry(run: RunData, entry: TraceEntry) -> EpisodeScore:
    trace = entry.trace
    episode = run.episodes.get(trace.episode_id)
    totals = trace.compute_totals() if trace.calls else trace.totals
    window = trace.params.get("window")
    row = EpisodeScore(
        variant=entry.label,
        variant_id=entry.variant_id,
        series=entry.series,
        method=trace.method,
        episode_id=trace.episode_id,
        task=trace.task,
        task_group=(episode.task_group if episode else None) or "all",
        level=episode.truth.level if episode and episode.truth else None,
        num_frames=trace.num_frames,
        view=trace.view,
        window=window if isinstance(window, int) else None,
        tokens=totals.total_tokens,
        calls=totals.calls,
    )
    if episode is not None and episode.truth is not None:
        s = score_progress(trace, episode)
        row.pearson, row.l2 = _finite(s.pearson), _finite(s.l2)
        row.voc, row.frame_corr = _finite(s.voc), _finite(s.frame_corr)
        row.non_expert_share = nonexpert_share(episode)
    _judged_metrics(row, run, entry)
    return row


def _judged_metrics(row: EpisodeScore, run: RunData, entry: TraceEntry) -> None:
    verdicts = run.verdicts.get(entry.key)
    if verdicts:
        vals = [v.verdict for v in verdicts.values()]
        row.error_rate = 100.0 * sum(v == "false" for v in vals) / len(vals)
        row.success_rate = 100.0 * sum(v == "true" for v in vals) / len(vals)
    answers = [a for a in run.qa.get(entry.key, []) if a.predicted is not None]
    if not answers:
        return
    row.qa_accuracy = 100.0 * sum(bool(a.predicted) == a.truth for a in answers) / len(answers)
    said_yes = [a for a in answers if a.predicted]
    if said_yes:
        row.qa_precision = 100.0 * sum(a.truth for a in said_yes) / len(said_yes)
    happened = [a for a in answers if a.truth]
    if happened:
        row.qa_recall = 100.0 * sum(bool(a.predicted) for a in happened) / len(happened)
    row.qa_time_diffs = [
        a.predicted_frame - a.truth_frame
        for a in answers
        if a.truth and a.predicted and a.truth_frame is not None and a.predicted_frame is not None
    ]


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
