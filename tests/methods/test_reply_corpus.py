"""The labelled reply corpus (tests/methods/replies/corpus.jsonl): every reply parses as
intended. Run this file directly for the accuracy per style:

    python tests/methods/test_reply_corpus.py
"""

from __future__ import annotations

import json
import math
import sys
from collections import Counter
from pathlib import Path

from rover.methods.parse import parse_frames, parse_step

CORPUS = Path(__file__).parent / "replies" / "corpus.jsonl"


def load() -> list[dict]:
    return [json.loads(line) for line in CORPUS.read_text(encoding="utf-8").splitlines() if line]


def _same(a: float | None, b: float | None) -> bool:
    return (a is None and b is None) or (
        a is not None and b is not None and math.isclose(a, b, abs_tol=1e-9)
    )


def mismatches(case: dict) -> list[str]:
    """How the parse differs from the label ([] when it matches)."""
    want, out = case["expect"], []
    if case["kind"] == "step":
        r = parse_step(case["reply"])
        got = {
            "description": r.description,
            "progress": r.progress,
            "new_subtask": r.new_subtask,
            "complete": r.task_complete,
        }
        for key, value in got.items():
            ok = _same(value, want[key]) if key == "progress" else value == want[key]
            if not ok:
                out.append(f"{key}: got {value!r}, want {want[key]!r}")
        if want["plan"] is not None and r.plan != want["plan"]:
            out.append(f"plan: got {r.plan!r}, want {want['plan']!r}")
        return out
    frames = parse_frames(case["reply"])
    if sorted(frames) != sorted(int(k) for k in want):
        out.append(f"frames: got {sorted(frames)}, want {sorted(int(k) for k in want)}")
    for k, w in want.items():
        a = frames.get(int(k))
        if a is None:
            continue
        if a.description != w["description"] or not _same(a.progress, w["progress"]):
            out.append(f"frame {k}: got {(a.description, a.progress)!r}, want {w!r}")
    return out


def test_corpus_is_large_and_varied():
    cases = load()
    assert len(cases) >= 300
    styles = {c["style"].split("/")[0] for c in cases}
    assert {"progress", "decompose", "complete", "parent", "trap", "frames"} <= styles


def test_every_labelled_reply_parses_as_intended():
    bad = {c["id"]: m for c in load() if (m := mismatches(c))}
    assert not bad, f"{len(bad)} replies misparsed: " + "; ".join(
        f"#{i}: {', '.join(m)}" for i, m in list(bad.items())[:10]
    )


if __name__ == "__main__":
    cases = load()
    total, wrong = Counter(), Counter()
    for c in cases:
        total[c["style"]] += 1
        if m := mismatches(c):
            wrong[c["style"]] += 1
            print(f"#{c['id']} {c['style']}: {'; '.join(m)}")
    ok = sum(total.values()) - sum(wrong.values())
    print(f"{ok}/{len(cases)} replies parsed as labelled ({100 * ok / len(cases):.1f}%)")
    sys.exit(0 if not wrong else 1)
