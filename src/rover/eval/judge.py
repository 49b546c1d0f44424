"""Task 2, frame-level reasoning: judge every frame description of a trace (App. C.2).

Two judges share one output shape (`Judgements`, saved under `judgements/` in a run):
the offline rule judge (`rover.eval.rule_judge`) and an LLM judge that sends the
description plus the frame's simulator facts, written out as plain sentences, to any
backend with the prompt in `prompts/judge.txt`. Error rate = share of judged frames with a
verifiably false statement; success rate = share with a verifiably true statement and no
false one (App. C.2).
"""

from __future__ import annotations

import asyncio
import re

from pydantic import BaseModel, Field

from rover.episode import Episode, FrameFacts
from rover.eval.prompts import build_prompt
from rover.eval.rule_judge import FrameJudgement, frame_verdict, judge_description
from rover.methods.trace import Trace
from rover.vlm.types import VLM, PromptMeta, SamplingParams


class FrameVerdictRecord(BaseModel):
    index: int  # original frame index
    position: int  # position in the video the method saw
    verdict: str  # "true" | "false" | "inconclusive"
    true_claims: list[str] = Field(default_factory=list)
    false_claims: list[str] = Field(default_factory=list)
    reason: str = ""


class Judgements(BaseModel):
    """All verdicts for one trace; the file `judgements/<episode>/<variant>.json`."""

    episode_id: str
    variant: str
    judge: str
    verdicts: list[FrameVerdictRecord]
    calls: int = 0
    total_tokens: int = 0
    has_facts: bool = True  # False for episodes without simulator facts (real videos)

    def rates(self) -> tuple[float, float, int]:
        """(error rate, success rate, judged frames); NaN without frames or facts."""
        n = len(self.verdicts)
        if n == 0 or not self.has_facts:
            return float("nan"), float("nan"), 0
        err = sum(v.verdict == "false" for v in self.verdicts) / n
        ok = sum(v.verdict == "true" for v in self.verdicts) / n
        return err, ok, n


def facts_to_text(facts: FrameFacts) -> str:
    """The simulator facts of one frame as short sentences an LLM judge can read."""
    lines = [f"- The gripper is {facts.gripper}."]
    if facts.gripper_opening is not None:
        lines.append(f"- Gripper opening: {facts.gripper_opening:.2f} (0 closed, 1 fully open).")
    lines.append(
        f"- The robot is holding the {facts.holding}."
        if facts.holding
        else "- The robot is not holding anything."
    )
    if facts.contacts:
        lines.append(f"- The gripper is touching: {', '.join(facts.contacts)}.")
    else:
        lines.append("- The gripper is not touching anything.")
    for name, obj in facts.objects.items():
        parts = ["lifted" if obj.lifted else "not lifted"]
        if obj.inside:
            parts.append(f"in {obj.inside}")
        if obj.on:
            parts.append(f"on {obj.on}")
        lines.append(f"- The {name} is {', '.join(parts)}.")
    for part, frac in facts.articulations.items():
        lines.append(f"- The {part} is {round(100 * frac)}% open/turned.")
    for b in facts.pressed:
        lines.append(f"- The {b} is pressed.")
    for pair, dist in facts.distances.items():
        lines.append(f"- Distance {pair}: {dist:.2f} m.")
    return "\n".join(lines)


_FIELD = re.compile(r"^\W*(true|false)\s+statements?\W*:\s*(.*)$", re.I | re.M)
_VERDICT = re.compile(r"verdict\W*:\W*(true|false|inconclusive)", re.I)
_NONE = {"", "none", "n/a", "nothing", "-", "no"}


def parse_judge_reply(text: str) -> FrameJudgement:
    """Read a judge reply; the statement lists decide, the Verdict line is a fallback."""
    lists: dict[str, list[str]] = {"true": [], "false": []}
    seen = False
    for m in _FIELD.finditer(text or ""):
        seen = True
        items = [x.strip(" .\"'*") for x in m.group(2).split(";")]
        lists[m.group(1).lower()] = [x for x in items if x.lower() not in _NONE]
    if seen:
        verdict = frame_verdict(len(lists["true"]), len(lists["false"]))
    else:
        m = _VERDICT.search(text or "")
        verdict = m.group(1).lower() if m else "inconclusive"  # type: ignore[assignment]
    return FrameJudgement(verdict, lists["true"], lists["false"], (text or "").strip()[:500])


def _frames(trace: Trace, episode: Episode) -> list[tuple[int, int, str | None, FrameFacts | None]]:
    where = {idx: pos for pos, idx in enumerate(episode.frame_indices)}
    facts = episode.truth.facts if episode.truth is not None else None
    out = []
    for f in trace.frames:
        pos = where.get(f.index)
        if pos is None:
            continue
        out.append((f.index, pos, f.description, facts[pos] if facts else None))
    return out


def _has_facts(episode: Episode) -> bool:
    return episode.truth is not None and episode.truth.facts is not None


def _record(index: int, pos: int, j: FrameJudgement) -> FrameVerdictRecord:
    """One frame's stored verdict from a judgement (rule judge or parsed LLM reply)."""
    return FrameVerdictRecord(
        index=index,
        position=pos,
        verdict=j.verdict,
        true_claims=j.true_claims,
        false_claims=j.false_claims,
        reason=j.reason,
    )


def rule_judge_trace(trace: Trace, episode: Episode, variant: str) -> Judgements:
    """Judge every frame of a trace with the offline rule judge."""
    verdicts = []
    for index, pos, desc, facts in _frames(trace, episode):
        verdicts.append(_record(index, pos, judge_description(desc, facts)))
    return Judgements(
        episode_id=episode.id,
        variant=variant,
        judge="rule",
        verdicts=verdicts,
        has_facts=_has_facts(episode),
    )


JUDGE_PARAMS = SamplingParams(temperature=0.0, max_tokens=400)


async def llm_judge_frame(
    vlm: VLM,
    task: str,
    description: str,
    facts: FrameFacts,
    index: int = 0,
    position: int = 0,
) -> tuple[FrameJudgement, int]:
    """One App. C.2 judge call: (parsed judgement, tokens used).

    The call goes through the backend like a method's call, so it is cached, retried and
    recorded the same way; `index`/`position` only label the prompt for tracing.
    """
    meta = PromptMeta(
        kind="judge.frame",
        frame_indices=[index],
        positions=[position],
        extra={"description": description, "facts": facts.model_dump(mode="json")},
    )
    prompt = build_prompt(
        "judge", meta, task=task, description=description, facts=facts_to_text(facts)
    )
    completion = await vlm.complete(prompt, JUDGE_PARAMS)
    return parse_judge_reply(completion.text), completion.usage.total_tokens


async def llm_judge_trace(
    trace: Trace, episode: Episode, variant: str, vlm: VLM, judge_name: str
) -> Judgements:
    """Judge every described frame of a trace with an LLM (one call per frame)."""
    usage = {"calls": 0, "tokens": 0}

    async def one(index: int, pos: int, desc: str | None, facts: FrameFacts | None):
        if not desc or facts is None:
            why = "no description" if not desc else "no simulator facts for this frame"
            return FrameVerdictRecord(index=index, position=pos, verdict="inconclusive", reason=why)
        judgement, tokens = await llm_judge_frame(vlm, episode.task, desc, facts, index, pos)
        usage["calls"] += 1
        usage["tokens"] += tokens
        return _record(index, pos, judgement)

    verdicts = await asyncio.gather(*(one(*f) for f in _frames(trace, episode)))
    return Judgements(
        episode_id=episode.id,
        variant=variant,
        judge=judge_name,
        verdicts=list(verdicts),
        calls=usage["calls"],
        total_tokens=usage["tokens"],
        has_facts=_has_facts(episode),
    )
