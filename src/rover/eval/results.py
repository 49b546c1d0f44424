"""From a run directory's files to metrics.json: per-trace rows and aggregate tables.

Everything is recomputed from the files (traces, judgements, QA answers, the episode
metadata saved at load time), never from in-memory state, so a resumed run and an
uninterrupted one produce identical metrics, and `compute_metrics` can be rerun alone.
"""

from __future__ import annotations

import json
import math
from typing import Any

from rover.episode import Episode
from rover.eval.aggregate import finite_or_none, group_mean_se, mean_se
from rover.eval.cost import cost_row, cost_table
from rover.eval.episodes import variant_episode
from rover.eval.error_analysis import ERROR_TYPES, error_table, video_errors
from rover.eval.judge import Judgements
from rover.eval.progress_metrics import (
    align,
    frame_subset_abs_error,
    frame_subset_pearson,
    score_progress,
)
from rover.eval.qa import QAAnswer, QAAnswers
from rover.eval.rundir import METRICS_FILE, SUMMARY_FILE, RunDir, write_json_atomic
from rover.eval.stratify import (
    FRAME_STRATA,
    TRACE_STRATA,
    context_bin,
    context_frames,
    state_types,
    trace_strata,
)
from rover.eval.variants import Variant
from rover.methods.trace import Trace
from rover.run import SCHEMA_VERSION
from rover.run.scorer import qa_scores, signed_distances

METRICS_SCHEMA = SCHEMA_VERSION
# rates (error, success, QA accuracy / precision / recall) are percentages, 0-100
TRACE_METRICS = (
    "pearson",
    "l2",
    "voc",
    "frame_corr",
    "error_rate",
    "success_rate",
    "inconclusive_rate",
    "qa_accuracy",
    "qa_precision",
    "qa_recall",
    "qa_signed_dt",
    "qa_abs_dt",
    "total_tokens",
    "calls",
)
FRAME_METRICS = ("pearson", "abs_error", "error_rate", "success_rate")
TABLE_OF = {
    "pearson": "progress",
    "l2": "progress",
    "voc": "progress",
    "frame_corr": "progress",
    "abs_error": "progress",
    "error_rate": "reasoning",
    "success_rate": "reasoning",
    "inconclusive_rate": "reasoning",
    "qa_accuracy": "qa",
    "qa_precision": "qa",
    "qa_recall": "qa",
    "qa_signed_dt": "qa",
    "qa_abs_dt": "qa",
    "total_tokens": "cost",
    "calls": "cost",
}


# every scored row carries these keys (None when that part of the evaluation did not run)
_SCORE_KEYS = (
    "pearson",
    "pearson_constant",
    "l2",
    "voc",
    "voc_constant",
    "frame_corr",
    "error_rate",
    "success_rate",
    "n_judged",
    "inconclusive_rate",
    "qa_accuracy",
    "qa_precision",
    "qa_recall",
    "qa_signed_dt",
    "qa_abs_dt",
    "qa_n",
    "qa_unreadable",
    "stage_error",
)


def _load(path, model):
    return model.model_validate_json(path.read_text()) if path.exists() else None


def _episode(rundir: RunDir, episode_id: str) -> Episode | None:
    path = rundir.episode_path(episode_id)
    if not path.exists():
        return None
    raw = json.loads(path.read_text())
    raw.pop("views", None)
    return Episode.model_validate(raw)


def compute_metrics(rundir: RunDir, config: dict[str, Any]) -> dict[str, Any]:
    """All numbers of a run as plain data (the content of metrics.json)."""
    variants = [Variant.model_validate(v) for v in config["variants"]]
    datasets = config.get("episode_datasets", {})
    errors = {(e["episode_id"], e["variant"]): e for e in rundir.errors()}
    rows: list[dict[str, Any]] = []
    frame_rows: list[dict[str, Any]] = []
    answers: dict[str, list[tuple[dict[str, Any], QAAnswer]]] = {}
    for eid in config["episodes"]:
        meta = _episode(rundir, eid)
        for v in variants:
            base = {
                "episode_id": eid,
                "variant": v.id,
                "label": v.label,
                "method": v.method,
                "backend": v.backend,
                "window": v.window,
                "frames_setting": v.frames,
                "dataset": datasets.get(eid),
            }
            trace = _load(rundir.trace_path(eid, v.id), Trace)
            if meta is None or trace is None:
                err = errors.get((eid, v.id), {}).get("error", "not run")
                rows.append({**base, "error": err})
                continue
            ep = variant_episode(meta, meta.frame_indices, v)
            judg = _load(rundir.stage_path("judge", eid, v.id), Judgements)
            qa = _load(rundir.stage_path("qa", eid, v.id), QAAnswers)
            row = {
                **base,
                **trace_strata(ep, trace, v.model_dump(), datasets.get(eid)),
                "dataset": datasets.get(eid),
                "backend": v.backend,
                "window": v.window,
                "n_frames": ep.num_frames,
                "task": ep.task,
                "error": None,
                "progress_source": ep.truth.progress_source if ep.truth else None,
                **dict.fromkeys(_SCORE_KEYS),
                **cost_row(trace),
            }
            if ep.truth is not None:
                s = score_progress(trace, ep)
                row.update(
                    pearson=s.pearson,
                    pearson_constant=s.pearson_constant,
                    l2=s.l2,
                    voc=s.voc,
                    voc_constant=s.voc_constant,
                    frame_corr=s.frame_corr,
                )
                frame_rows += _frame_rows(row, trace, ep, judg)
            if judg is not None:
                err, ok, n = judg.rates()
                row.update(
                    error_rate=100.0 * err,
                    success_rate=100.0 * ok,
                    n_judged=n,
                    inconclusive_rate=100.0 - 100.0 * (err + ok),
                )
            if qa is not None:
                sc = qa_scores(qa.answers)
                row.update(
                    qa_accuracy=sc["accuracy"],
                    qa_precision=sc["precision"],
                    qa_recall=sc["recall"],
                    qa_signed_dt=sc["signed_distance"],
                    qa_abs_dt=sc["abs_distance"],
                    qa_n=sc["qa_n"],
                    qa_unreadable=sc["unreadable"],
                    qa_dts=signed_distances(qa.answers),
                )
                answers.setdefault(v.id, []).extend((row, a) for a in qa.answers)
            for k, flag in video_errors(trace, ep, judg).items():
                row[f"err_{k}"] = flag
            if (eid, v.id) in errors:  # the trace is done but a later stage failed
                e = errors[(eid, v.id)]
                row["stage_error"] = f"{e.get('stage')}: {e.get('error')}"
            rows.append(row)
    # App. L's per-dataset table: several datasets, or real videos scored against frame number
    multi_dataset = len({r.get("dataset") for r in rows}) > 1 or any(
        r.get("progress_source") == "frame_number" for r in rows
    )
    out = {
        "schema_version": METRICS_SCHEMA,
        "variants": [v.model_dump(mode="json") for v in variants],
        "per_trace": [_clean(r) for r in rows],
        "aggregates": _aggregates(rows, frame_rows, variants, multi_dataset),
        "qa_pooled": _qa_pooled(answers, variants),
        "cost": cost_table([r for r in rows if r.get("error") is None]),
        "error_analysis": error_table([r for r in rows if r.get("error") is None]),
        "counts": _counts(rows),
        "notes": _notes(rows, frame_rows),
        "judges": judge_facts(config),
    }
    return out


INCONCLUSIVE_WARN = 30.0  # % of a method's judged frames


def _notes(rows: list[dict[str, Any]], frame_rows: list[dict[str, Any]]) -> list[str]:
    """One line per analysis that does not apply to this run, saying why (never zeros)."""
    ok = [_clean(r) for r in rows if r.get("error") is None]  # NaN -> None
    notes = []
    if ok and not any(r.get("error_rate") is not None for r in ok):
        if any(r.get("n_judged") is not None for r in ok):  # judged, but nothing to judge by
            notes.append(
                "Frame reasoning (Task 2: error / success rate, by state type and frames in "
                "context) and the perception row of the error analysis are omitted: no video "
                "in this run has simulator facts to judge descriptions against."
            )
    frame_truth = [r for r in ok if r.get("progress_source") == "frame_number"]
    if frame_truth:
        notes.append(
            f"{len({r['episode_id'] for r in frame_truth})} video(s) have no measured progress: "
            "their ground truth is the frame number (App. L), so Pearson r and L2 there "
            "measure agreement with steady progress, and the derived reasoning-error rule "
            "(a predicted drop against rising truth) is not applied to them."
        )
    if ok and not any(r["by"] == "state_type" for r in frame_rows):
        notes.append("By state type (App. H): omitted, no video carries state-type labels.")
    if ok and not any(r.get("qa_n") for r in ok):
        notes.append("Video QA (Task 3): omitted, no video in this run carries QA questions.")
    return notes


def judge_facts(config: dict[str, Any]) -> dict[str, Any]:
    """Which judge and answerer scored the run, with their measured agreement
    (rover.eval.judge_cards) so every view can print it beside their numbers."""
    out: dict[str, Any] = {"judge": config.get("judge"), "answerer": config.get("answerer")}
    try:
        from rover.eval.judge_cards import judge_card
    except ImportError:  # pragma: no cover - the cards ship with rover
        return out
    for role in ("judge", "answerer"):
        try:
            card = judge_card(role, str(out[role] or ""))
        except Exception:  # noqa: BLE001 - the card is extra information only
            card = None
        if card is not None:
            out[f"{role}_name"] = card.name
            out[f"{role}_agreement"] = card.short()
            out[f"{role}_line"] = card.line()
    return out


def inconclusive_warnings(metrics: dict[str, Any]) -> dict[str, float]:
    """Variant id -> mean inconclusive share (%) where it exceeds INCONCLUSIVE_WARN."""
    out = {}
    for a in metrics.get("aggregates", []):
        if (
            a["metric"] == "inconclusive_rate"
            and a["by"] == "all"
            and a["mean"] is not None
            and a["mean"] > INCONCLUSIVE_WARN
        ):
            out[a["variant"]] = a["mean"]
    return out


def _frame_rows(
    row: dict[str, Any], trace: Trace, ep: Episode, judg: Judgements | None
) -> list[dict[str, Any]]:
    """Per (trace, frame-level stratum) numbers: App. G state type x context length."""
    a = align(trace, ep)
    st = state_types(ep)
    ctx = context_frames(trace)
    # without simulator facts every verdict is inconclusive: no rate, not a rate of 0
    verdict = {v.index: v.verdict for v in judg.verdicts} if judg and judg.has_facts else {}
    labels = {
        "state_type": [st.get(i) for i in a.indices],
        "context": [context_bin(ctx.get(i)) for i in a.indices],
    }
    out = []
    for by, groups in labels.items():
        for g in sorted({x for x in groups if x is not None}):
            keep = [x == g for x in groups]
            vs = [verdict[i] for i, k in zip(a.indices, keep, strict=True) if k and i in verdict]
            out.append(
                {
                    "variant": row["variant"],
                    "method": row["method"],
                    "episode_id": row["episode_id"],
                    "by": by,
                    "group": g,
                    "n": sum(keep),
                    "pearson": frame_subset_pearson(a, keep),
                    "abs_error": frame_subset_abs_error(a, keep),
                    "error_rate": _pct(vs, "false"),
                    "success_rate": _pct(vs, "true"),
                }
            )
    return out


def _pct(verdicts: list[str], which: str) -> float:
    return 100.0 * sum(x == which for x in verdicts) / len(verdicts) if verdicts else math.nan


def _aggregates(rows, frame_rows, variants: list[Variant], multi_dataset: bool):
    ok = [r for r in rows if r.get("error") is None]
    out: list[dict[str, Any]] = []
    strata = ("all",) + TRACE_STRATA + (("dataset",) if multi_dataset else ())
    for v in variants:
        vr = [r for r in ok if r["variant"] == v.id]
        for by in strata:
            key = (lambda r: "all") if by == "all" else by
            for metric in TRACE_METRICS:
                for group, (mean, se, n) in sorted(
                    group_mean_se(vr, metric, key).items(), key=lambda kv: str(kv[0])
                ):
                    out.append(_agg(TABLE_OF[metric], by, group, v, metric, mean, se, n))
        fr = [r for r in frame_rows if r["variant"] == v.id]
        for by in FRAME_STRATA:
            sub = [r for r in fr if r["by"] == by]
            for metric in FRAME_METRICS:
                for group, (mean, se, n) in sorted(group_mean_se(sub, metric, "group").items()):
                    out.append(_agg(TABLE_OF[metric], by, group, v, metric, mean, se, n))
    return out


def _agg(table, by, group, v: Variant, metric, mean, se, n) -> dict[str, Any]:
    return {
        "table": table,
        "by": by,
        "group": group,
        "variant": v.id,
        "label": v.label,
        "method": v.method,
        "metric": metric,
        "mean": finite_or_none(mean),
        "se": finite_or_none(se),
        "n": n,
    }


def _qa_pooled(answers, variants: list[Variant]) -> list[dict[str, Any]]:
    """QA scores over all questions of a variant, overall and per task group."""
    out = []
    for v in variants:
        pairs = answers.get(v.id, [])
        groups: dict[str, list[QAAnswer]] = {"all": [a for _, a in pairs]}
        for row, a in pairs:
            groups.setdefault(f"task_group={row.get('task_group')}", []).append(a)
        for g, items in groups.items():
            sc = qa_scores(items)
            by, _, group = g.partition("=")
            out.append(
                {
                    "variant": v.id,
                    "label": v.label,
                    "method": v.method,
                    "by": "all" if g == "all" else by,
                    "group": "all" if g == "all" else group,
                    **{k: finite_or_none(x) if isinstance(x, float) else x for k, x in sc.items()},
                    "signed_distances": signed_distances(items),
                }
            )
    return out


def _counts(rows: list[dict[str, Any]]) -> dict[str, Any]:
    ok = [r for r in rows if r.get("error") is None]
    return {
        "units": len(rows),
        "traces": len(ok),
        "failed": len(rows) - len(ok),
        "voc_constant": sum(bool(r.get("voc_constant")) for r in ok),
        "pearson_constant": sum(bool(r.get("pearson_constant")) for r in ok),
        "pearson_undefined": sum(
            r.get("pearson") is not None and math.isnan(r["pearson"]) for r in ok
        ),
        "parse_failures": sum(int(r.get("parse_failures") or 0) for r in ok),
        "truncated_replies": sum(int(r.get("truncated") or 0) for r in ok),
    }


def _clean(row: dict[str, Any]) -> dict[str, Any]:
    return {k: finite_or_none(v) if isinstance(v, float) else v for k, v in row.items()}


def mean_of(
    metrics: dict[str, Any], variant: str, metric: str, by: str = "all", group: Any = "all"
) -> tuple[float | None, float | None, int]:
    """Look one aggregate up: (mean, se, n); (None, None, 0) when absent."""
    for a in metrics["aggregates"]:
        if (
            a["variant"] == variant
            and a["metric"] == metric
            and a["by"] == by
            and (a["group"] == group)
        ):
            return a["mean"], a["se"], a["n"]
    return None, None, 0


def write_results(rundir: RunDir, metrics: dict[str, Any]) -> None:
    """metrics.json and summary.md, both atomically."""
    from rover.eval.summary import render_summary

    write_json_atomic(rundir.root / METRICS_FILE, metrics)
    run = json.loads(rundir.run_file.read_text()) if rundir.run_file.exists() else {}
    text = render_summary(metrics, run)
    tmp = rundir.root / (SUMMARY_FILE + ".tmp")
    tmp.write_text(text)
    tmp.replace(rundir.root / SUMMARY_FILE)


__all__ = ["ERROR_TYPES", "compute_metrics", "mean_of", "mean_se", "write_results"]
