"""Agreement of a judge / answerer with the corpus labels, and the confusion behind it.

Used by `benchmarks/judge_agreement.py` (which prints and stores the numbers) and by the
tests (which hold the rule judge and answerer to them). The LLM paths run through a real
backend object — in the benchmark a loopback OpenAI-compatible server whose scripted
model replies the way chat models format things — so prompt building, the HTTP call,
reply parsing and the verdict rule are all exercised.
"""

from __future__ import annotations

import asyncio
from collections import Counter
from dataclasses import dataclass, field

from rover.eval.agreement import FrameCase, QACase
from rover.eval.judge import llm_judge_frame
from rover.eval.qa import concatenated, llm_answer_question
from rover.eval.qa_events import asserted_states, first_event_position
from rover.eval.rule_judge import judge_description

VERDICTS = ("true", "false", "inconclusive")
ANSWERS = ("yes", "no")


@dataclass
class Agreement:
    """Share of cases where the prediction equals the label, with the confusion matrix.

    `confusion[label][predicted]` counts cases; `misses` keeps the disagreeing case ids
    with what was predicted, for reading what remains out of reach.
    """

    labels: tuple[str, ...]
    n: int = 0
    agree: int = 0
    confusion: dict[str, dict[str, int]] = field(default_factory=dict)
    misses: list[tuple[str, str, str]] = field(default_factory=list)  # (id, label, predicted)
    by_group: dict[str, list[int]] = field(default_factory=dict)  # group -> [agree, n]
    frame_agree: int = 0  # QA: both say yes and name the same frame
    frame_n: int = 0

    def add(self, case_id: str, label: str, predicted: str, groups: tuple[str, ...] = ()) -> None:
        self.n += 1
        ok = label == predicted
        self.agree += ok
        row = self.confusion.setdefault(label, {p: 0 for p in self.labels})
        row[predicted] = row.get(predicted, 0) + 1
        if not ok:
            self.misses.append((case_id, label, predicted))
        for g in groups:
            cell = self.by_group.setdefault(g, [0, 0])
            cell[0] += ok
            cell[1] += 1

    @property
    def rate(self) -> float:
        return self.agree / self.n if self.n else float("nan")

    def as_json(self) -> dict:
        return {
            "agreement": round(self.rate, 4),
            "n": self.n,
            "confusion": {lab: self.confusion.get(lab, {}) for lab in self.labels},
            "by_group": {g: {"agreement": a / n, "n": n} for g, (a, n) in self.by_group.items()},
            "frame_agreement": (
                round(self.frame_agree / self.frame_n, 4) if self.frame_n else None
            ),
            "frame_n": self.frame_n,
            "misses": [list(m) for m in self.misses],
        }


def rule_judge_agreement(cases: list[FrameCase]) -> Agreement:
    out = Agreement(VERDICTS)
    for c in cases:
        j = judge_description(c.description, c.facts, task=c.task)
        out.add(c.id, c.label, j.verdict, (f"style:{c.style}", f"family:{c.family}"))
    return out


def rule_answer(case: QACase) -> int | None:
    """The rule answerer's position (index into the case's descriptions) or None."""
    states = asserted_states(list(case.descriptions), task=case.task)
    return first_event_position(case.item, states, case.qa)


def _qa_add(out: Agreement, case: QACase, yes: bool | None, pos: int | None) -> None:
    label = "yes" if case.item.answer else "no"
    predicted = "unreadable" if yes is None else ("yes" if yes else "no")
    out.add(case.id, label, predicted, (f"event:{case.item.event}", f"style:{case.style}"))
    if case.item.answer and yes:
        out.frame_n += 1
        out.frame_agree += pos == case.item.frame


def rule_qa_agreement(cases: list[QACase]) -> Agreement:
    out = Agreement(ANSWERS)
    for c in cases:
        pos = rule_answer(c)
        _qa_add(out, c, pos is not None, pos)
    return out


async def llm_judge_agreement(cases: list[FrameCase], vlm) -> Agreement:
    """Agreement of the LLM judge path (`llm_judge_frame`) through `vlm`."""
    out = Agreement(VERDICTS)
    judged = await asyncio.gather(
        *(llm_judge_frame(vlm, c.task, c.description, c.facts, c.frame, c.frame) for c in cases)
    )
    for c, (j, _) in zip(cases, judged, strict=True):
        out.add(c.id, c.label, j.verdict, (f"style:{c.style}",))
    return out


async def llm_qa_agreement(cases: list[QACase], vlm) -> Agreement:
    """Agreement of the LLM answerer path (`llm_answer_question`) through `vlm`."""
    out = Agreement(ANSWERS)
    replies = await asyncio.gather(
        *(
            llm_answer_question(
                vlm, c.task, concatenated(list(c.descriptions)), c.item, len(c.descriptions)
            )
            for c in cases
        )
    )
    for c, (yes, pos, _, _) in zip(cases, replies, strict=True):
        _qa_add(out, c, yes, pos)
    return out


def label_counts(cases) -> Counter:
    return Counter(getattr(c, "label", None) or ("yes" if c.item.answer else "no") for c in cases)
