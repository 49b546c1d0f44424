"""The labelled agreement corpus for the Task 2 judge and the Task 3 answerer.

`frames.json` holds frame descriptions written the way GPT-4o, Gemini 2.5 and Qwen2.5-VL
write them, each paired with the simulator facts of a real generated frame (stored in the
file, so regenerating datasets never changes the corpus) and labelled true / false /
inconclusive with the statements that decide it. `qa.json` holds video-QA cases: a short
sequence of such descriptions, a question, and the yes/no answer (with the first frame)
that the descriptions support. Each case belongs to the development half ("dev") or the
held-out half ("heldout"); `benchmarks/judge_agreement.py` reports on the held-out half and
writes `measured.json`, which `rover.eval.judge_cards` reads.

How the cases were written is in `build.py` (phrase banks per claim, model styles, the
labelling rule); the hand-written cases are in `handwritten.py`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cache
from importlib import resources
from typing import Any

from rover.episode import FrameFacts, QAItem

CORPUS_VERSION = "1"
SPLITS = ("dev", "heldout")


@dataclass(frozen=True)
class FrameCase:
    """One labelled frame description."""

    id: str
    split: str
    style: str  # "gpt-4o" | "gemini-2.5" | "qwen2.5-vl" | "handwritten"
    episode: str
    frame: int
    task: str
    family: str
    facts: FrameFacts
    description: str
    label: str  # "true" | "false" | "inconclusive"
    true_claims: list[str] = field(default_factory=list)
    false_claims: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class QACase:
    """One labelled video question over a sequence of frame descriptions."""

    id: str
    split: str
    style: str
    episode: str
    task: str
    family: str
    positions: list[int]  # episode frame positions the descriptions belong to
    descriptions: list[str]
    item: QAItem  # the question; `answer`/`frame` are the label (frame: index in descriptions)
    qa: list[QAItem]  # every question of the episode (the drop question reads the place one)


def _read(name: str) -> list[dict[str, Any]]:
    text = resources.files("rover.eval").joinpath("agreement", name).read_text()
    return json.loads(text)["cases"]


@cache
def frame_cases() -> tuple[FrameCase, ...]:
    """Every labelled frame description, dev and held-out."""
    out = []
    for c in _read("frames.json"):
        c = dict(c)
        c["facts"] = FrameFacts.model_validate(c["facts"])
        out.append(FrameCase(**c))
    return tuple(out)


@cache
def qa_cases() -> tuple[QACase, ...]:
    """Every labelled QA case, dev and held-out."""
    out = []
    for c in _read("qa.json"):
        c = dict(c)
        c["item"] = QAItem.model_validate(c["item"])
        c["qa"] = [QAItem.model_validate(q) for q in c["qa"]]
        out.append(QACase(**c))
    return tuple(out)


def split(cases, name: str) -> list:
    """The cases of one half ('dev' or 'heldout')."""
    if name not in SPLITS:
        raise ValueError(f"split must be one of {SPLITS}, got {name!r}")
    return [c for c in cases if c.split == name]
