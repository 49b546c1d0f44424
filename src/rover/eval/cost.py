"""Inference cost (App. G): tokens and VLM calls per video, by method and frame count.

Prompt tokens are split into the part the provider reported serving from its prompt-prefix
cache (`cached_prompt_tokens`: OpenAI/vLLM `cached_tokens`, Gemini
`cached_content_token_count`) and the rest; the split is computed here once and every view
(metrics.json, summary.md, the HTML report, the terminal line) reads these rows.
"""

from __future__ import annotations

from typing import Any

from rover.eval.aggregate import finite_or_none, group_mean_se
from rover.methods.trace import Totals, Trace


def trace_totals(trace: Trace) -> Totals:
    """The trace's totals, recomputed from its calls when the method left them empty."""
    t = trace.totals
    if t.calls == 0 and trace.calls:
        return trace.compute_totals()
    return t


def cost_row(trace: Trace) -> dict[str, Any]:
    t = trace_totals(trace)
    return {
        "calls": t.calls,
        "total_tokens": t.total_tokens,
        "prompt_tokens": t.prompt_tokens,
        "completion_tokens": t.completion_tokens,
        "image_tokens": t.image_tokens,
        "cached_prompt_tokens": t.cached_prompt_tokens,
        "uncached_prompt_tokens": max(t.prompt_tokens - t.cached_prompt_tokens, 0),
        "cached_calls": t.cached_calls,
        "parse_failures": t.parse_failures,
        "latency_s": t.latency_s,
        "truncated": truncated_replies(t),
    }


def truncated_replies(t: Totals) -> int | None:
    """Replies cut off at max_tokens, when the method records them (else None)."""
    for name in ("truncated", "truncations", "truncated_replies", "truncated_calls"):
        if name in type(t).model_fields:
            return int(getattr(t, name) or 0)
    return None


COST_METRICS = (
    "total_tokens",
    "calls",
    "prompt_tokens",
    "completion_tokens",
    "cached_prompt_tokens",
    "uncached_prompt_tokens",
)


def cost_table(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Mean ± SE tokens and calls per video for each (variant, frames) pair."""
    out = []
    ok = [r for r in rows if not r.get("error")]
    for metric in COST_METRICS:
        stats = group_mean_se(ok, metric, lambda r: (r["variant"], r["method"], _frames(r)))
        for (variant, method, n_frames), (mean, se, n) in sorted(
            stats.items(), key=lambda kv: tuple(map(str, kv[0]))
        ):
            out.append(
                {
                    "variant": variant,
                    "method": method,
                    "frames": n_frames,
                    "metric": metric,
                    "mean": finite_or_none(mean),
                    "se": finite_or_none(se),
                    "n": n,
                }
            )
    return out


def _frames(row: dict[str, Any]) -> int | str:
    """The frame-count setting a row ran at ('all': each video's own length, which varies
    on real data), or the video's frame count for rows that do not say."""
    if "frames_setting" in row:
        return row["frames_setting"] or "all"
    return row["n_frames"]
