"""Who judged Task 2 and answered Task 3, and how often they agree with human labels.

The paper reports that its LLM judge agreed with human judgement on 97.5% of 200 examples
(App. C.2). Our numbers come from `benchmarks/judge_agreement.py`, which runs each judge
and answerer on the held-out half of the labelled corpus in `rover/eval/agreement/` and
writes `rover/eval/agreement/measured.json`. That file is the one place the agreement
lives; run summaries and the report read it through `judge_card`, so a judge is never
named without its measured agreement (or without saying that it was not measured).

An LLM judge (`openai:...`, `gemini:...`) has a measured card only once someone ran the
benchmark with `--model SPEC` against that model (its numbers are stored under the spec).
Otherwise its card says the agreement was not measured and carries that of the LLM path
with a scripted model (prompt, reply parsing and verdict rule only).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

MEASURED_FILE = "measured.json"
KINDS = ("judge", "answerer")
_RULE_KEYS = {"judge": "rule_judge", "answerer": "rule_answerer"}
_LLM_KEYS = {"judge": "llm_judge_scripted", "answerer": "llm_answerer_scripted"}
_OFF = {"", "none", "off", "skip"}
FRESH_GROUP = "style:handwritten-fresh"


@dataclass(frozen=True)
class JudgeCard:
    """A judge or answerer with its measured held-out agreement.

    `agreement` is the share of held-out corpus cases on which it gives the human label
    (verdict true/false/inconclusive for a judge, yes/no for an answerer); None when it
    was not measured for this judge. `n` is the number of held-out cases behind it.
    """

    kind: str  # "judge" | "answerer"
    spec: str  # "rule" or the backend spec given on the command line
    name: str  # display name
    agreement: float | None
    n: int = 0
    corpus: str = ""  # corpus version the number was measured on
    note: str = ""
    # agreement on the held-out descriptions written by hand in fresh words (not from the
    # phrase banks the rules were developed beside): the harder, more honest number
    fresh_agreement: float | None = None
    fresh_n: int = 0

    def short(self) -> str:
        """The agreement alone, for a table cell or after the judge's name."""
        if self.agreement is None:
            return "not measured"
        out = f"{100 * self.agreement:.1f}% on {self.n} held-out cases"
        if self.fresh_agreement is not None:
            out += f" ({100 * self.fresh_agreement:.1f}% on the {self.fresh_n} in fresh words)"
        return out

    def __str__(self) -> str:
        return self.short()

    def line(self) -> str:
        """One line for summaries: name and agreement (or why there is none)."""
        what = "Task 2 judge" if self.kind == "judge" else "Task 3 QA answerer"
        if self.agreement is None:
            return f"{what}: {self.name} — agreement not measured. {self.note}".strip()
        tail = f"; {self.note}" if self.note else ""
        agree = f"agreement with the labels {self.short()}, corpus v{self.corpus}"
        return f"{what}: {self.name} — {agree}{tail}"


@cache
def measured() -> dict[str, Any]:
    """The contents of `measured.json` ({} when the benchmark has not written it)."""
    path = resources.files("rover.eval").joinpath("agreement", MEASURED_FILE)
    try:
        return json.loads(path.read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return {}


def _entry(key: str) -> dict[str, Any] | None:
    entry = measured().get("judges", {}).get(key)
    return entry if isinstance(entry, dict) else None


def judge_card(kind: str, spec: str = "rule") -> JudgeCard | None:
    """The card for the Task 2 judge (`kind="judge"`) or Task 3 answerer ("answerer").

    `spec` is what `--judge` / `--answerer` was given; None comes back when that stage
    was switched off ('none'). Use: `judge_card("judge", run["judge"]).line()`.
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    spec = (spec or "").strip()
    if spec.lower() in _OFF:
        return None
    corpus = str(measured().get("corpus_version", ""))
    if spec.lower() == "rule":
        entry = _entry(_RULE_KEYS[kind])
        name = "rule judge" if kind == "judge" else "rule QA answerer"
        if entry is None:
            return JudgeCard(kind, "rule", name, None, note="run benchmarks/judge_agreement.py")
        fresh = entry.get("by_group", {}).get(FRESH_GROUP)
        return JudgeCard(
            kind,
            "rule",
            name,
            float(entry["agreement"]),
            int(entry["n"]),
            corpus,
            fresh_agreement=float(fresh["agreement"]) if fresh else None,
            fresh_n=int(fresh["n"]) if fresh else 0,
        )
    model = measured().get("models", {}).get(spec, {}).get(kind)
    if isinstance(model, dict):
        return JudgeCard(
            kind, spec, f"LLM {spec}", float(model["agreement"]), int(model["n"]), corpus
        )
    scripted = _entry(_LLM_KEYS[kind])
    note = "its agreement depends on the model; the paper measured 97.5% for GPT-4.5."
    if scripted is not None:
        note += (
            f" The LLM path itself (prompt, reply parsing, verdict rule) agrees on "
            f"{100 * float(scripted['agreement']):.1f}% of {int(scripted['n'])} held-out "
            "cases with a scripted model."
        )
    return JudgeCard(kind, spec, f"LLM {spec}", None, corpus=corpus, note=note)
