"""summary.md: the paper-style tables of a run, rendered from metrics.json's data."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rover.eval.aggregate import fmt_mean_se
from rover.methods.info import display_name

MAIN_COLUMNS = [
    # (header, source, metric, digits); every column is a per-video mean ± SE, and
    # rates are percentages (0-100) everywhere: here, the terminal and the HTML report
    ("Pearson r", "agg", "pearson", 2),
    ("L2", "agg", "l2", 1),
    ("VOC", "agg", "voc", 2),
    ("Corr. frame #", "agg", "frame_corr", 2),
    ("Error rate %", "agg", "error_rate", 1),
    ("Success rate %", "agg", "success_rate", 1),
    ("QA acc. %", "agg", "qa_accuracy", 1),
    ("QA prec. %", "agg", "qa_precision", 1),
    ("QA recall %", "agg", "qa_recall", 1),
    ("QA Δt", "agg", "qa_signed_dt", 1),
    ("QA |Δt|", "agg", "qa_abs_dt", 1),
    ("Tokens/video", "agg", "total_tokens", 0),
    ("Calls/video", "agg", "calls", 1),
]
POOLED_COLUMNS = [  # (header, qa_pooled key, digits): over all questions of a variant
    ("Questions", "qa_n", 0),
    ("Unreadable", "unreadable", 0),
    ("QA acc. %", "accuracy", 1),
    ("QA prec. %", "precision", 1),
    ("QA recall %", "recall", 1),
    ("QA Δt", "signed_distance", 1),
    ("QA |Δt|", "abs_distance", 1),
]
METRIC_NAMES = {
    "pearson": "Pearson r",
    "l2": "L2 distance",
    "error_rate": "error rate",
    "success_rate": "success rate",
    "voc": "VOC",
}
LEVEL_NAMES = {
    "task_group": "task group",
    "level": "level",
    "nonexpert": "non-expert share",
    "state_type": "state type",
    "context": "frames in context",
    "view": "camera view",
    "backend": "backend",
    "frames": "frames per video",
    "window": "window",
    "dataset": "dataset",
}


def _agg_index(metrics: dict[str, Any]) -> dict[tuple, dict[str, Any]]:
    return {
        (a["variant"], a["metric"], a["by"], str(a["group"])): a
        for a in metrics.get("aggregates", [])
    }


COMPACT = (
    "Pearson r",
    "L2",
    "VOC",
    "Error rate %",
    "Success rate %",
    "QA acc. %",
    "Tokens/video",
    "Calls/video",
)


def main_rows(metrics: dict[str, Any], compact: bool = False) -> tuple[list[str], list[list[str]]]:
    """(headers, rows) of the main table: one row per variant (compact: for terminals)."""
    idx = _agg_index(metrics)
    columns = [c for c in MAIN_COLUMNS if not compact or c[0] in COMPACT]
    # a column no variant has a number for (no judge, no QA, real videos) is left out
    columns = [
        c
        for c in columns
        if any(
            (a := idx.get((v["id"], c[2], "all", "all"))) is not None and a["mean"] is not None
            for v in metrics.get("variants", [])
        )
    ]
    with_view = views_vary(metrics)
    headers = ["Method"] + (["View"] if with_view else []) + [c[0] for c in columns] + ["n"]
    rows = []
    for v in metrics.get("variants", []):
        cells = [v["label"] or v["id"]] + ([v["view"] or "own"] if with_view else [])
        n = 0
        for _, _src, metric, digits in columns:
            a = idx.get((v["id"], metric, "all", "all"))
            if a is None:
                cells.append("–")
                continue
            n = max(n, a["n"])
            cells.append(_fmt(a["mean"], None if compact else a["se"], digits))
        cells.append(str(n))
        rows.append(cells)
    return headers, rows


def views_vary(metrics: dict[str, Any]) -> bool:
    """True when the run sweeps camera views (then tables carry a View column)."""
    return len({v.get("view") for v in metrics.get("variants", [])}) > 1


def variant_names(metrics: dict[str, Any]) -> dict[str, str]:
    """Variant id -> its name in column headers (the view added when views vary)."""
    with_view = views_vary(metrics)
    return {
        v["id"]: (v["label"] or v["id"]) + (f" · {v['view'] or 'own'} view" if with_view else "")
        for v in metrics.get("variants", [])
    }


def pooled_rows(metrics: dict[str, Any]) -> tuple[list[str], list[list[str]]] | None:
    """Secondary QA table: every question of a variant pooled (no SE); None without QA."""
    rows = [q for q in metrics.get("qa_pooled", []) if q["by"] == "all" and q.get("qa_n")]
    if not rows:
        return None
    labels = variant_names(metrics)
    body = [
        [labels.get(q["variant"], q["variant"])]
        + [_fmt(q.get(k), None, d) if d else str(q.get(k) or 0) for _, k, d in POOLED_COLUMNS]
        for q in rows
    ]
    return ["Method"] + [c[0] for c in POOLED_COLUMNS], body


def _fmt(mean: Any, se: Any, digits: int) -> str:
    if mean is None:
        return "–"
    if digits == 0:
        return f"{mean:,.0f}" + (f" ± {se:,.0f}" if se is not None else "")
    return fmt_mean_se(mean, float("nan") if se is None else se, digits)


def pivot(
    metrics: dict[str, Any], metric: str, by: str, digits: int = 2
) -> tuple[list[str], list[list[str]]] | None:
    """Rows = groups of `by`, columns = variants; None when the run has no such groups."""
    aggs = [a for a in metrics.get("aggregates", []) if a["by"] == by and a["metric"] == metric]
    if not any(a["mean"] is not None for a in aggs):
        return None  # nothing measured: omitted (metrics.json notes say why), never zeros
    if {str(a["group"]) for a in aggs} <= {"unknown", "None"}:
        return None  # one unlabelled group (real videos have no task group): no breakdown
    variants = [
        v for v in metrics.get("variants", []) if any(a["variant"] == v["id"] for a in aggs)
    ]
    groups = sorted({a["group"] for a in aggs}, key=_group_key)
    cell = {(a["variant"], a["group"]): a for a in aggs}
    names = variant_names(metrics)
    headers = [LEVEL_NAMES.get(by, by)] + [names[v["id"]] for v in variants]
    rows = []
    for g in groups:
        row = [str(g)]
        for v in variants:
            a = cell.get((v["id"], g))
            ok = a is not None and a["mean"] is not None
            row.append(_fmt(a["mean"], a["se"], digits) + f" (n={a['n']})" if ok else "–")
        rows.append(row)
    return headers, rows


SWEEPS = [  # (variant field, title, metrics)
    ("frames", "App. I: by frames per video", ("pearson", "error_rate")),
    ("view", "App. J: by camera view", ("pearson", "error_rate")),
    ("backend", "App. K: by backbone VLM", ("pearson", "l2", "error_rate", "success_rate")),
    ("window", "App. M: by sliding-window size", ("pearson", "error_rate")),
]
_SHORT = {"backend": "b", "frames": "f", "window": "w", "view": "v"}


def sweep_pivot(
    metrics: dict[str, Any], dim: str, metric: str, digits: int = 2
) -> tuple[list[str], list[list[str]]] | None:
    """Rows = values of one swept setting, columns = the other variant settings."""
    variants = metrics.get("variants", [])
    values = {v[dim] for v in variants if v[dim] is not None}
    if len(values) < 2:
        return None
    others = [
        k
        for k in _SHORT
        if k != dim and len({v[k] for v in variants if k != "window" or v[k] is not None}) > 1
    ]

    def column(v: dict[str, Any]) -> str:
        extra = [f"{_SHORT[k]}={v[k]}" for k in others if v[k] is not None]
        return display_name(v["method"]) + (f" [{', '.join(extra)}]" if extra else "")

    idx = _agg_index(metrics)
    cols = list(dict.fromkeys(column(v) for v in variants if v[dim] is not None))
    cell: dict[tuple[str, Any], str] = {}
    for v in variants:
        a = idx.get((v["id"], metric, "all", "all"))
        if v[dim] is not None and a is not None and a["mean"] is not None:
            cell[(column(v), v[dim])] = _fmt(a["mean"], a["se"], digits) + f" (n={a['n']})"
    rows = [
        [str(val)] + [cell.get((c, val), "–") for c in cols]
        for val in sorted(values, key=_group_key)
    ]
    return [LEVEL_NAMES.get(dim, dim)] + cols, rows


def _group_key(g: Any) -> tuple:
    s = str(g)
    head = s.split("-")[0].rstrip("%")
    return (0, float(head), s) if head.replace(".", "").isdigit() else (1, 0.0, s)


def markdown_table(headers: list[str], rows: list[list[str]]) -> str:
    esc = [[c.replace("|", "\\|") for c in r] for r in [headers] + rows]
    lines = ["| " + " | ".join(esc[0]) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(r) + " |" for r in esc[1:]]
    return "\n".join(lines)


@dataclass
class Table:
    """One titled table of a run; summary.md and the HTML report render the same list."""

    id: str
    title: str
    headers: list[str]
    rows: list[list[str]]
    note: str = ""
    warnings: list[str] = field(default_factory=list)


MAIN_NOTE = (
    "Rates are percentages. QA columns are per-video means (the paper's and its "
    "reference code's aggregation); Δt is predicted minus true frame (negative: too "
    "early), |Δt| its size, over correctly answered 'yes' questions."
)
PIVOTS = [  # (id, title, metric, by, digits)
    ("pearson-group", "Task 1: Pearson r by task group (Fig. 3)", "pearson", "task_group", 2),
    ("pearson-level", "Task 1: Pearson r by level (Fig. 3)", "pearson", "level", 2),
    ("l2-level", "Task 1: L2 distance by level (App. A)", "l2", "level", 1),
    (
        "framecorr-nonexpert",
        "Task 1: correlation with frame number by non-expert share (App. A)",
        "frame_corr",
        "nonexpert",
        2,
    ),
    ("error-level", "Task 2: error rate % by level (Fig. 5)", "error_rate", "level", 1),
    ("success-level", "Task 2: success rate % by level (App. A)", "success_rate", "level", 1),
    ("error-group", "Task 2: error rate % by task group", "error_rate", "task_group", 1),
    ("pearson-state", "App. H: Pearson r by state type", "pearson", "state_type", 2),
    ("pearson-context", "App. H: Pearson r by frames in context", "pearson", "context", 2),
    ("error-state", "App. H: error rate % by state type", "error_rate", "state_type", 1),
    ("error-context", "App. H: error rate % by frames in context", "error_rate", "context", 1),
    ("voc-dataset", "App. L: VOC by dataset", "voc", "dataset", 3),
    (
        "framecorr-dataset",
        "App. L: correlation with frame number by dataset",
        "frame_corr",
        "dataset",
        3,
    ),
    ("pearson-dataset", "App. L: Pearson r with ground truth by dataset", "pearson", "dataset", 3),
]


def run_tables(metrics: dict[str, Any]) -> list[Table]:
    """Every table of the run, in reading order (the main table first)."""
    from rover.eval.results import inconclusive_warnings

    labels = variant_names(metrics)
    warnings = [
        f"{labels.get(vid, vid)}: the judge left {share:.0f}% of its frames inconclusive, so "
        "its error rate rests on fewer than 70% of its frames."
        for vid, share in inconclusive_warnings(metrics).items()
    ]
    out = [
        Table(
            "main",
            "Main results (mean ± standard error over videos)",
            *main_rows(metrics),
            note=MAIN_NOTE,
            warnings=warnings,
        )
    ]
    pooled = pooled_rows(metrics)
    if pooled is not None:
        out.append(Table("qa-pooled", "Video QA pooled over questions (secondary)", *pooled))
    for tid, title, metric, by, digits in PIVOTS:
        t = pivot(metrics, metric, by, digits)
        if t is not None:
            out.append(Table(tid, title, *t))
    for dim, title, names in SWEEPS:
        for metric in names:
            t = sweep_pivot(metrics, dim, metric, 1 if metric in ("l2", "error_rate") else 2)
            if t is not None:
                name = f"{title}: {METRIC_NAMES.get(metric, metric)}"
                out.append(Table(f"sweep-{dim}-{metric}", name, *t))
    for t in (_cost_table(metrics), _error_table(metrics)):
        if t is not None:
            out.append(t)
    return out


def render_summary(metrics: dict[str, Any], run: dict[str, Any]) -> str:
    """The whole summary.md."""
    out = ["# rover eval summary", ""]
    src = run.get("dataset") or ", ".join(run.get("sources", []))
    out += [
        f"- data: `{src}`  ",
        f"- episodes: {len(run.get('episodes', []))}  ",
        f"- backends: {', '.join(run.get('backends', []))}  ",
        f"- judge: {_judge_line(metrics, run, 'judge')}, "
        f"QA answerer: {_judge_line(metrics, run, 'answerer')}",
        "",
    ]
    if any(b == "oracle" for b in run.get("backends", [])):
        out += [
            "> Traces from the `oracle` backend answer from simulator ground truth: they are",
            "> an upper bound / pipeline check, not a VLM's performance.",
            "",
        ]
    tables = run_tables(metrics)
    notes = metrics.get("notes", [])
    for i, t in enumerate(tables):
        out += [f"## {t.title}", "", markdown_table(t.headers, t.rows), ""]
        if t.note:
            out += [t.note, ""]
        if t.warnings:
            out += [f"- **{w}**" for w in t.warnings] + [""]
        if i == 0 and notes:
            out += ["## Not applicable to this run", ""] + [f"- {n}" for n in notes] + [""]
    out += _counts_section(metrics)
    return "\n".join(out).rstrip() + "\n"


COST_NOTE = (
    "Cached prompt tokens: the part of the prompt the provider reported serving from its "
    "prompt-prefix cache (billed at its cached-input price where it has one); 0 when it "
    "reports none (estimated usage, the oracle, servers without prefix caching)."
)


def _cost_table(metrics: dict[str, Any]) -> Table | None:
    rows: dict[tuple, dict[str, Any]] = {}
    labels = variant_names(metrics)
    for c in metrics.get("cost", []):
        rows.setdefault((c["variant"], c["frames"]), {})[c["metric"]] = c
    if not rows:
        return None
    body = []
    for (variant, frames), m in sorted(rows.items(), key=lambda kv: (str(kv[0][1]), kv[0][0])):
        tok, calls = m.get("total_tokens"), m.get("calls")
        cached, fresh = m.get("cached_prompt_tokens"), m.get("uncached_prompt_tokens")
        body.append(
            [
                labels.get(variant, variant),
                str(frames),
                _fmt(tok["mean"], tok["se"], 0) if tok else "–",
                _fmt(cached["mean"], cached["se"], 0) if cached else "–",
                _fmt(fresh["mean"], fresh["se"], 0) if fresh else "–",
                _fmt(calls["mean"], calls["se"], 1) if calls else "–",
                str(tok["n"] if tok else 0),
            ]
        )
    headers = [
        "Method",
        "Frames",
        "Avg tokens per video",
        "Cached prompt tokens",
        "Uncached prompt tokens",
        "Avg VLM calls per video",
        "n",
    ]
    return Table("cost", "Inference cost (App. F)", headers, body, note=COST_NOTE)


def prompt_cache_line(metrics: dict[str, Any]) -> str | None:
    """One terminal line from the cost table: each method's share of prompt tokens the
    provider served from its prefix cache; None when no provider reported any."""
    labels = variant_names(metrics)
    cells: dict[tuple, dict[str, Any]] = {}
    for c in metrics.get("cost", []):
        cells.setdefault((c["variant"], c["frames"]), {})[c["metric"]] = c["mean"]
    parts = []
    for (variant, frames), m in sorted(cells.items(), key=lambda kv: (str(kv[0][1]), kv[0][0])):
        cached, prompt = m.get("cached_prompt_tokens"), m.get("prompt_tokens")
        if cached and prompt:
            at = f" at {frames} frames" if len({k[1] for k in cells}) > 1 else ""
            parts.append(f"{labels.get(variant, variant)}{at} {100 * cached / prompt:.0f}%")
    if not parts:
        return None
    return "prompt tokens served from the provider's prefix cache: " + ", ".join(parts)


def _error_table(metrics: dict[str, Any]) -> Table | None:
    rows = metrics.get("error_analysis", [])
    if not any(r["mean"] is not None for r in rows):
        return None  # no rule applies to any video (metrics.json notes say why)
    variants = list(dict.fromkeys(r["variant"] for r in rows))
    labels = variant_names(metrics)
    names = {
        "incorrect_subtask": "Incorrect subtasks",
        "redundant_subtask": "Redundant subtasks",
        "perception": "Perception error",
        "reasoning": "Reasoning error",
        "total": "Total",
    }
    cell = {(r["variant"], r["error_type"]): r for r in rows}
    body = []
    for k, name in names.items():
        line = [name]
        for v in variants:
            r = cell.get((v, k))
            line.append("NA" if not r or r["mean"] is None else f"{r['mean']:.0f}%")
        body.append(line)
    return Table(
        "errors",
        "Error analysis: share of videos with each error type "
        "(Sec. 5 Table 1, types in App. C.4; derived)",
        ["Error type"] + [labels.get(v, v) for v in variants],
        body,
        note="Derivation rules: docs/evaluation.md#error-analysis.",
    )


def _judge_line(metrics: dict[str, Any], run: dict[str, Any], role: str) -> str:
    facts = metrics.get("judges", {})
    name = facts.get(f"{role}_name") or facts.get(role) or run.get(role)
    agree = facts.get(f"{role}_agreement")
    return f"{name} (measured agreement: {agree})" if agree is not None else str(name)


def _counts_section(metrics: dict[str, Any]) -> list[str]:
    c = metrics.get("counts", {})
    out = [
        "## Counts",
        "",
        f"- traces scored: {c.get('traces', 0)} of {c.get('units', 0)} "
        f"(failed or not run: {c.get('failed', 0)})",
        f"- constant predictions (VOC and Pearson scored 0): {c.get('voc_constant', 0)}",
        f"- Pearson undefined (constant ground truth, left out): {c.get('pearson_undefined', 0)}",
        f"- parse failures in traces: {c.get('parse_failures', 0)}",
        f"- truncated replies (stopped at max_tokens): {c.get('truncated_replies', 0)}",
        "",
    ]
    failed = [
        {**r, "error": r.get("error") or r.get("stage_error")}
        for r in metrics.get("per_trace", [])
        if r.get("error") or r.get("stage_error")
    ]
    if failed:
        out += ["### Failed units", ""]
        for r in failed[:30]:
            out.append(f"- `{r['episode_id']}` / `{r['variant']}`: {str(r['error'])[:200]}")
        if len(failed) > 30:
            out.append(f"- ... and {len(failed) - 30} more (errors.jsonl)")
        out.append("")
    return out
