"""Agreement of the Task 2 judges and Task 3 answerers with the labelled corpus.

    python benchmarks/judge_agreement.py [--split heldout|dev|all] [--json PATH]
                                         [--no-write] [--misses N] [--model SPEC]

Runs, on one half of `rover/eval/agreement/` (held-out by default):

* the rule judge (`rover.eval.rule_judge`) on every frame description: agreement of its
  true / false / inconclusive verdict with the label, and the confusion matrix;
* the rule QA answerer on every QA case: yes/no agreement, confusion, and how often both
  say yes and name the same frame;
* the LLM judge and the LLM answerer paths (prompt -> backend -> reply parsing ->
  verdict) through a loopback OpenAI-compatible server whose scripted model always means
  the label but formats its reply the way chat models do (markdown, prose around the
  fields, bullet lists, JSON, a lost last line). This measures our side of the LLM judge;
  the model's own agreement needs a real model (the paper measured 97.5% for GPT-4.5):
  `--model SPEC` runs the same cases through that backend as judge and answerer, and
  stores its numbers so `rover eval --judge SPEC` summaries can quote them.

The paper's bar (App. C.2) and this project's: at least 90% on the held-out half for the
rule judge and the rule answerer. With the default split and without --no-write it
stores the numbers in `rover/eval/agreement/measured.json`, which run summaries and the
report read (`rover.eval.judge_cards`).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import re
import sys
from datetime import UTC, datetime
from pathlib import Path

from rover.eval.agreement import CORPUS_VERSION, frame_cases, qa_cases, split
from rover.eval.agreement.measure import (
    ANSWERS,
    VERDICTS,
    Agreement,
    llm_judge_agreement,
    llm_qa_agreement,
    rule_judge_agreement,
    rule_qa_agreement,
)
from rover.eval.agreement.scripted import scripted_answer

TARGET = 0.90
MEASURED = Path(__file__).resolve().parents[1] / "src/rover/eval/agreement/measured.json"


async def _llm_paths(fcases, qcases) -> tuple[Agreement, Agreement]:
    from rover.vlm.config import BackendConfig
    from rover.vlm.loader import load_vlm
    from rover.vlm.testing import OpenAICompatServer

    with OpenAICompatServer() as server:
        server.answer = scripted_answer(fcases, qcases)
        config = BackendConfig(no_cache=True, concurrency=16, retry_base_wait_s=0.001)
        vlm = load_vlm(f"openai:scripted-judge@{server.base_url}", config)
        judge = await llm_judge_agreement(fcases, vlm)
        qa = await llm_qa_agreement(qcases, vlm)
    return judge, qa


async def _model_paths(spec: str, fcases, qcases) -> tuple[Agreement, Agreement]:
    """The LLM judge and answerer through a real backend (cached like method calls)."""
    from rover.vlm.config import BackendConfig
    from rover.vlm.loader import load_vlm

    vlm = load_vlm(spec, BackendConfig())
    return await llm_judge_agreement(fcases, vlm), await llm_qa_agreement(qcases, vlm)


def _previous_models() -> dict:
    """Models measured before, kept while the corpus is the same version."""
    try:
        old = json.loads(MEASURED.read_text())
    except (OSError, ValueError):
        return {}
    return old.get("models", {}) if old.get("corpus_version") == CORPUS_VERSION else {}


# --- tables -------------------------------------------------------------------------------


def _table(title: str, a: Agreement, labels: tuple[str, ...]) -> str:
    cols = list(labels) + (["unreadable"] if labels == ANSWERS else [])
    lines = [
        f"{title}: {100 * a.rate:.1f}% agreement ({a.agree}/{a.n})",
        "  label \\ predicted  " + "".join(f"{c:>14}" for c in cols),
    ]
    for lab in labels:
        row = a.confusion.get(lab, {})
        lines.append(f"  {lab:<18} " + "".join(f"{row.get(c, 0):>14}" for c in cols))
    if a.frame_n:
        lines.append(
            f"  same first frame when both say yes: {100 * a.frame_agree / a.frame_n:.1f}% "
            f"({a.frame_agree}/{a.frame_n})"
        )
    groups = sorted(a.by_group.items())
    if groups:
        lines.append(
            "  by group: " + ", ".join(f"{g} {100 * x / n:.0f}% ({n})" for g, (x, n) in groups)
        )
    return "\n".join(lines)


def _misses(a: Agreement, by_id: dict, k: int) -> str:
    lines = []
    for cid, lab, pred in a.misses[:k]:
        c = by_id[cid]
        text = getattr(c, "description", None) or c.item.question
        text = re.sub(r"\s+", " ", text)[:150]
        lines.append(f"  {cid} label={lab} predicted={pred} [{c.style}] {text}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--split", choices=["heldout", "dev", "all"], default="heldout")
    ap.add_argument("--json", type=Path, help="write every number here as JSON")
    ap.add_argument("--no-write", action="store_true", help="do not update measured.json")
    ap.add_argument("--misses", type=int, default=15, help="disagreements to list per judge")
    ap.add_argument(
        "--model",
        help="also measure a real LLM as judge and answerer (any backend spec, e.g. "
        "openai:gpt-4o); its numbers are stored under that spec and shown on its card",
    )
    args = ap.parse_args(argv)
    if args.model:
        from rover.vlm.loader import parse_spec

        try:
            if parse_spec(args.model)[0] == "oracle":
                raise ValueError("the oracle cannot judge")
        except Exception as e:  # noqa: BLE001 - one line, before any call
            print(f"error: --model {args.model!r}: {e}", file=sys.stderr)
            return 2

    def pick(cases):
        return list(cases) if args.split == "all" else split(cases, args.split)

    fcases, qcases = pick(frame_cases()), pick(qa_cases())
    rule_j = rule_judge_agreement(fcases)
    rule_q = rule_qa_agreement(qcases)
    llm_j, llm_q = asyncio.run(_llm_paths(fcases, qcases))
    model = asyncio.run(_model_paths(args.model, fcases, qcases)) if args.model else None

    by_id = {c.id: c for c in fcases} | {c.id: c for c in qcases}
    print(
        f"corpus v{CORPUS_VERSION}, split {args.split}: {len(fcases)} frame descriptions, "
        f"{len(qcases)} QA cases\n"
    )
    print(_table("Rule judge (Task 2)", rule_j, VERDICTS))
    print(_misses(rule_j, by_id, args.misses))
    print()
    print(_table("Rule QA answerer (Task 3)", rule_q, ANSWERS))
    print(_misses(rule_q, by_id, args.misses))
    print()
    print(_table("LLM judge path, scripted model", llm_j, VERDICTS))
    print(_table("LLM answerer path, scripted model", llm_q, ANSWERS))
    if model is not None:
        print(_table(f"LLM judge {args.model}", model[0], VERDICTS))
        print(_misses(model[0], by_id, args.misses))
        print(_table(f"LLM answerer {args.model}", model[1], ANSWERS))
        print(_misses(model[1], by_id, args.misses))
    ok = rule_j.rate >= TARGET and rule_q.rate >= TARGET
    print(
        f"\ntarget >= {100 * TARGET:.0f}% for the rule judge and answerer: "
        f"{'met' if ok else 'NOT met'}"
    )

    result = {
        "corpus_version": CORPUS_VERSION,
        "split": args.split,
        "measured_at": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "command": "python benchmarks/judge_agreement.py",
        "judges": {
            "rule_judge": rule_j.as_json(),
            "rule_answerer": rule_q.as_json(),
            "llm_judge_scripted": llm_j.as_json(),
            "llm_answerer_scripted": llm_q.as_json(),
        },
        "models": _previous_models(),
    }
    if model is not None:
        result["models"][args.model] = {"judge": model[0].as_json(), "answerer": model[1].as_json()}
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
    if args.split == "heldout" and not args.no_write:
        slim = json.loads(json.dumps(result))
        entries = list(slim["judges"].values())
        entries += [e for m in slim["models"].values() for e in m.values()]
        for entry in entries:
            entry.pop("misses", None)
        MEASURED.write_text(json.dumps(slim, indent=1) + "\n")
        print(f"wrote {MEASURED.relative_to(MEASURED.parents[4])}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
