"""A scripted judge / answerer model for the loopback server: it always means the label.

It stands in for an LLM in `benchmarks/judge_agreement.py` and the tests, so the LLM
judge and answerer paths (prompt building, the HTTP call through the real OpenAI SDK,
reply parsing, the verdict rule) are measured on the corpus without a model. Its replies
vary the way chat models lay such answers out: the exact format, bold labels, prose around
the fields, bullet lists under headings, JSON in a code fence, and a reply cut off before
its Verdict line. Disagreement with the labels is therefore ours, never the model's.
"""

from __future__ import annotations

import json

from rover.eval.judge import facts_to_text
from rover.eval.prompts import build_prompt
from rover.eval.qa import concatenated
from rover.vlm.types import PromptMeta

JUDGE_STYLES = 6
QA_STYLES = 4


def judge_reply(true: list[str], false: list[str], verdict: str, style: int) -> str:
    """A reply that means the label, in one of the ways chat models lay such replies out."""
    t = "; ".join(true) or "none"
    f = "; ".join(false) or "none"
    if style == 0:
        return f"True statements: {t}\nFalse statements: {f}\nVerdict: {verdict}"
    if style == 1:
        return f"**True statements:** {t}\n**False statements:** {f}\n\n**Verdict:** {verdict}"
    if style == 2:
        return (
            "Let me compare the description with the ground-truth state.\n\n"
            f"True statements: {t}\nFalse statements: {f}\n\n"
            f"Verdict: {verdict.upper()}. That follows from the statements above."
        )
    if style == 3:
        tl = "\n".join(f"- {x}" for x in true) or "- none"
        fl = "\n".join(f"- {x}" for x in false) or "- none"
        return f"### True statements:\n{tl}\n### False statements:\n{fl}\n### Verdict: {verdict}"
    if style == 4:
        body = {"true_statements": true, "false_statements": false, "verdict": verdict}
        return "```json\n" + json.dumps(body) + "\n```"
    # style 5: the reply ran into max_tokens after the two lists (no Verdict line)
    return f"True statements: {t}\nFalse statements: {f}\nVerd"


def qa_reply(yes: bool, frame: int | None, style: int) -> str:
    ans = "yes" if yes else "no"
    fr = str(frame + 1) if yes and frame is not None else "none"
    if style == 0:
        return f"Answer: {ans}\nFrame: {fr}"
    if style == 1:
        return f"**Answer:** {ans.capitalize()}\n**Frame:** {fr}"
    if style == 2:
        if yes:
            return f"Yes. According to the descriptions this first happens in frame {fr}."
        return "No, none of the descriptions show that happening."
    return f"Answer: {ans.upper()}\nFrame: {'#' + fr if yes else 'N/A'}"


def _user_text(body: dict) -> str:
    for m in body.get("messages", []):
        if m.get("role") == "user":
            c = m.get("content")
            if isinstance(c, str):
                return c
            return "".join(p.get("text", "") for p in c if isinstance(p, dict))
    return ""


def scripted_answer(fcases, qcases):
    """The server's answer function: looks the prompt up, replies with the case's label."""
    judge_by_prompt, qa_by_prompt = {}, {}
    for i, c in enumerate(fcases):
        p = build_prompt(
            "judge",
            PromptMeta(kind="scripted"),
            task=c.task,
            description=c.description,
            facts=facts_to_text(c.facts),
        )
        judge_by_prompt[p.messages[1].content] = (c, i % JUDGE_STYLES)
    for i, c in enumerate(qcases):
        ctx = concatenated(list(c.descriptions))
        meta = PromptMeta(kind="scripted")
        p = build_prompt("qa", meta, task=c.task, descriptions=ctx, question=c.item.question)
        qa_by_prompt[p.messages[1].content] = (c, i % QA_STYLES)

    def answer(body: dict) -> str:
        text = _user_text(body)
        if text in judge_by_prompt:
            c, style = judge_by_prompt[text]
            return judge_reply(c.true_claims, c.false_claims, c.label, style)
        if text in qa_by_prompt:
            c, style = qa_by_prompt[text]
            return qa_reply(c.item.answer, c.item.frame, style)
        return "I am not sure what you are asking."

    return answer
