"""Task 3, video QA (App. C.3): answer "Did the robot X? If so, when?" from descriptions.

The questions come with the episode (`episode.truth.qa`). Answers use only a trace's
frame descriptions, concatenated as "Frame i: ..." (i from 1): either an LLM through any
backend (prompt `prompts/qa.txt`, one call per question, as in the paper) or the offline
rule answerer, which reads the claims in each description and returns the first frame
whose description asserts the event. Scores: accuracy, precision and recall of the yes/no
answer, and the signed / absolute distance in frames between the predicted and the true
time for questions both say happened (negative = the method claims it too early).
"""

from __future__ import annotations

import asyncio
import re

from pydantic import BaseModel, Field

from rover.episode import Episode, QAItem
from rover.eval.prompts import build_prompt
from rover.eval.qa_events import asserted_states, first_event_position
from rover.methods.trace import Trace
from rover.run.scorer import qa_scores  # noqa: F401 - scoring lives in the one scorer
from rover.vlm.types import VLM, PromptMeta, SamplingParams


class QAAnswer(BaseModel):
    question: str
    template: str = ""
    event: str | None = None
    object: str | None = None
    truth: bool
    truth_frame: int | None = None  # position in the video the method saw
    predicted: bool | None = None  # None when the reply could not be read
    predicted_frame: int | None = None
    truth_index: int | None = None  # original frame indices of the same frames
    predicted_index: int | None = None
    raw: str = ""


class QAAnswers(BaseModel):
    """All answers for one trace; the file `qa/<episode>/<variant>.json`."""

    episode_id: str
    variant: str
    answerer: str
    answers: list[QAAnswer] = Field(default_factory=list)
    calls: int = 0
    total_tokens: int = 0


def descriptions_by_position(trace: Trace, episode: Episode) -> list[str | None]:
    """One description per episode position (None where the trace has none)."""
    where = {idx: pos for pos, idx in enumerate(episode.frame_indices)}
    out: list[str | None] = [None] * episode.num_frames
    for f in trace.frames:
        if f.index in where:
            out[where[f.index]] = f.description
    return out


def concatenated(descriptions: list[str | None]) -> str:
    """'Frame 1: ...' lines, the context the paper's QA model reads."""
    return "\n".join(
        f"Frame {i + 1}: {d or '(no description)'}" for i, d in enumerate(descriptions)
    )


def _answer(item: QAItem, episode: Episode, predicted: bool | None, pos: int | None, raw: str):
    idx = episode.frame_indices
    return QAAnswer(
        question=item.question,
        template=item.template,
        event=item.event,
        object=item.object,
        truth=item.answer,
        truth_frame=item.frame if item.answer else None,
        predicted=predicted,
        predicted_frame=pos if predicted else None,
        truth_index=idx[item.frame] if item.answer and item.frame is not None else None,
        predicted_index=idx[pos] if predicted and pos is not None else None,
        raw=raw,
    )


def rule_answer_trace(trace: Trace, episode: Episode, variant: str) -> QAAnswers:
    """Answer every question from the claims in the trace's descriptions."""
    qa = episode.truth.qa if episode.truth is not None else []
    states = asserted_states(descriptions_by_position(trace, episode))
    answers = []
    for item in qa:
        pos = first_event_position(item, states, qa)
        answers.append(_answer(item, episode, pos is not None, pos, "rule"))
    return QAAnswers(episode_id=episode.id, variant=variant, answerer="rule", answers=answers)


_YES = re.compile(r"answer\W*:\W*(yes|no)\b", re.I)
_FRAME = re.compile(r"frame\W*:\W*(?:#\s*)?(\d+|none)", re.I)


def parse_qa_reply(text: str, num_frames: int) -> tuple[bool | None, int | None]:
    """(yes/no, 0-based position) from a reply; tolerant of a bare leading yes/no."""
    text = text or ""
    m = _YES.search(text)
    if m:
        yes: bool | None = m.group(1).lower() == "yes"
    else:
        head = text.strip().lower()
        yes = True if head.startswith("yes") else (False if head.startswith("no") else None)
    pos = None
    f = _FRAME.search(text)
    if f is None:
        f = re.search(r"\bframe\s+(\d+)", text, re.I)
    if yes and f and f.group(1).lower() != "none":
        pos = min(max(int(f.group(1)) - 1, 0), num_frames - 1)
    return yes, pos


QA_PARAMS = SamplingParams(temperature=0.0, max_tokens=100)


async def llm_answer_question(
    vlm: VLM, task: str, context: str, item: QAItem, num_frames: int
) -> tuple[bool | None, int | None, str, int]:
    """One App. C.3 call: (yes/no, 0-based frame, reply text, tokens used).

    `context` is the concatenated "Frame i: ..." descriptions; the call is cached and
    retried by the backend like any method call.
    """
    meta = PromptMeta(
        kind="qa.answer",
        extra={"question": item.question, "event": item.event, "object": item.object},
    )
    prompt = build_prompt("qa", meta, task=task, descriptions=context, question=item.question)
    completion = await vlm.complete(prompt, QA_PARAMS)
    yes, pos = parse_qa_reply(completion.text, num_frames)
    return yes, pos, completion.text, completion.usage.total_tokens


async def llm_answer_trace(
    trace: Trace, episode: Episode, variant: str, vlm: VLM, answerer: str
) -> QAAnswers:
    """Answer each question with one LLM call over all descriptions."""
    qa = episode.truth.qa if episode.truth is not None else []
    context = concatenated(descriptions_by_position(trace, episode))
    usage = {"calls": 0, "tokens": 0}

    async def one(item: QAItem) -> QAAnswer:
        yes, pos, text, tokens = await llm_answer_question(
            vlm, episode.task, context, item, episode.num_frames
        )
        usage["calls"] += 1
        usage["tokens"] += tokens
        return _answer(item, episode, yes, pos, text.strip()[:300])

    answers = await asyncio.gather(*(one(q) for q in qa))
    return QAAnswers(
        episode_id=episode.id,
        variant=variant,
        answerer=answerer,
        answers=list(answers),
        calls=usage["calls"],
        total_tokens=usage["tokens"],
    )
