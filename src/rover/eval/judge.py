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
import json
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
    others = [o for o in getattr(facts, "robot_contacts", []) if o not in facts.contacts]
    if others:
        lines.append(f"- Other parts of the robot (not the gripper) touch: {', '.join(others)}.")
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


_FIELD = re.compile(
    r"^[\s#>*_\-•]*(?P<kind>true|false)\s+statements?[\s*_]*(?::|$)[\s*_]*(?P<rest>.*)$", re.I
)
_VERDICT = re.compile(r"verdict[\s*_\"']*:?[\s*_\"']*(true|false|inconclusive)\b", re.I)
_BULLET = re.compile(r"^\s*(?:[-*•]|\d+[.)])\s+(.*)$")
_NONE = {"", "none", "n/a", "na", "nothing", "-", "no", "none.", "[]", "null"}


def _items(text: str) -> list[str]:
    items = [x.strip(" .\"'*`[]") for x in re.split(r";|\s\|\s", text)]
    return [x for x in items if x.lower().strip(" .") not in _NONE]


def _json_reply(text: str) -> FrameJudgement | None:
    """A reply written as a JSON object (some models do, fenced or not)."""
    m = re.search(r"\{.*\}", text, re.S)
    if not m:
        return None
    try:
        body = json.loads(m.group(0))
    except ValueError:
        return None
    if not isinstance(body, dict):
        return None
    lists: dict[str, list[str]] = {"true": [], "false": []}
    seen, verdict = set(), None
    for key, value in body.items():
        k = str(key).lower()
        kind = "true" if k.startswith("true") else ("false" if k.startswith("false") else None)
        if kind and "statement" in k:
            seen.add(kind)
            vals = value if isinstance(value, list) else [value]
            lists[kind] = [str(v) for v in vals if v and str(v).lower() not in _NONE]
        elif k == "verdict" and str(value).lower() in ("true", "false", "inconclusive"):
            verdict = str(value).lower()
    if not seen and verdict is None:
        return None
    if seen == {"true", "false"}:
        verdict = frame_verdict(len(lists["true"]), len(lists["false"]))
    verdict = verdict or "inconclusive"
    return FrameJudgement(verdict, lists["true"], lists["false"], text.strip()[:500])  # type: ignore[arg-type]


def parse_judge_reply(text: str) -> FrameJudgement:
    """Read a judge reply: "True statements: ..." / "False statements: ..." / "Verdict: ...".

    Tolerates markdown (bold labels, headings), prose around the fields, lists written as
    bullets under their label, and JSON. The two statement lists decide the verdict by
    App. C.2's rule when both are there; otherwise the Verdict line does; a reply with
    neither (cut off, or no format at all) is inconclusive.
    """
    text = text or ""
    lists: dict[str, list[str]] = {"true": [], "false": []}
    seen: set[str] = set()
    current: str | None = None
    for raw in text.splitlines():
        line = raw.replace("**", "").replace("__", "")
        m = _FIELD.match(line)
        if m:
            current = m.group("kind").lower()
            seen.add(current)
            lists[current] = _items(m.group("rest"))
            continue
        b = _BULLET.match(line)
        if current and b:
            lists[current] += _items(b.group(1))
            continue
        if line.strip():
            current = None
    v = _VERDICT.search(text.replace("**", ""))
    parsed = _json_reply(text) if not seen else None
    if seen == {"true", "false"}:
        verdict = frame_verdict(len(lists["true"]), len(lists["false"]))
    elif parsed is not None:
        return parsed
    elif v:
        verdict = v.group(1).lower()
    else:
        verdict = "false" if lists["false"] else "inconclusive"
    return FrameJudgement(verdict, lists["true"], lists["false"], text.strip()[:500])  # type: ignore[arg-type]


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
