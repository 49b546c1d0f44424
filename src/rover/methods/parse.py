"""Reading model replies: tolerant of prose, markdown and JSON, and never raising.

Real VLMs rarely follow the answer format to the letter: they bold the labels, answer in
JSON, write "45.5 %", "-10%" or "about 120 percent", wrap the subtask in quotes, or
forget a field. Every function here returns `None` (or an empty result) for a reply it
cannot use instead of raising, so the methods can re-ask once with a format reminder
and then record a parse failure, carrying the last value forward.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field

_NUM = r"[-+−–]?\s*\d+(?:[.,]\d+)?"
_NEEDS_TO = re.compile(r"the\s+robot\s+needs\s+to\s*[:\-–]?\s*(.*)", re.I)
_PLAN = re.compile(r"new\s+sub\s*-?\s*tasks?\s*[:\-–]\s*(.*)", re.I)
_DESC = re.compile(r"frame\s+description\s*[:\-–=]\s*(.*)", re.I)
_PCT_LINE = re.compile(
    r"(?:sub\s*-?\s*task|task)?\s*(?:completion|progress)\s*(?:percentage|percent|value)?"
    r"\s*(?:\(%\))?\s*[:\-–=]\s*(.*)",
    re.I,
)
_NEXT = re.compile(r"\[\s*next[\s_-]*frame\s*\]", re.I)
_COMPLETE = re.compile(r"\b(?:task|subtask)\s+(?:is\s+)?(?:now\s+)?complete(?:d)?\b", re.I)
_FRAME_HEADER = re.compile(r"^\W*frame\s*#?\s*(\d+)\s*(?:\W|$)(.*)$", re.I)
_NUMBER = re.compile(_NUM)
# the well-formed block, parsed without the general machinery (GVL replies hold hundreds)
_FAST_DESC = re.compile(r"frame\s+description\s*:\s*(.+)", re.I)
_FAST_PCT = re.compile(rf"completion\s+percentage\s*:\s*({_NUM})\s*%", re.I)


@dataclass
class FrameAnswer:
    """One frame's description and progress as the model gave them (either may be missing)."""

    description: str | None = None
    progress: float | None = None


@dataclass
class StepReply:
    """A ROVER step or parent-turn reply, reduced to what the algorithm branches on."""

    description: str | None = None
    progress: float | None = None
    next_frame: bool = False
    new_subtask: str | None = None
    plan: list[str] = field(default_factory=list)
    task_complete: bool = False

    @property
    def usable_step(self) -> bool:
        """A step reply must either predict progress or name a new subtask."""
        return self.progress is not None or self.new_subtask is not None or self.task_complete


def clean(text: object) -> str:
    """Strip markdown emphasis, code fences and headings; tolerate non-strings."""
    if not isinstance(text, str):
        return ""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    text = re.sub(r"```[a-zA-Z]*", "", text)
    text = text.replace("**", "").replace("__", "").replace("`", "")
    text = re.sub(r"(?m)^\s*#{1,6}\s*", "", text)
    text = re.sub(r"(?m)^\s*(?:[-*•>]|\d+\.)\s+(?=\S)", "", text)
    return text


def parse_percentage(value: object) -> float | None:
    """The first finite number in `value` ("45%", "-10.5 %", "about 120 percent", 0.5)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        v = float(value)
        return v if math.isfinite(v) else None
    if not isinstance(value, str):
        return None
    m = _NUMBER.search(value)
    if not m:
        return None
    s = re.sub(r"\s", "", m.group(0)).replace("−", "-").replace("–", "-").replace(",", ".")
    try:
        v = float(s)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def _strip_subtask(s: str) -> str:
    s = s.strip().strip("\"'“”‘’[]{}()").strip()
    s = _NEXT.sub("", s).strip()
    return s.rstrip(".").strip().strip("\"'“”‘’").strip()


def _split_list(s: str) -> list[str]:
    """A list written as JSON, Python or comma/semicolon separated text."""
    s = s.strip()
    try:
        val = json.loads(s.replace("'", '"'))
        if isinstance(val, list):
            return [str(v).strip() for v in val if str(v).strip()]
    except (ValueError, TypeError):
        pass
    inner = s.strip("[]")
    parts = re.findall(r"[\"'‘“]([^\"'’”]+)[\"'’”]", inner) or re.split(r"[;,]", inner)
    return [p for p in (_strip_subtask(x) for x in parts) if p]


def _json_object(text: str) -> dict | None:
    m = re.search(r"\{.*\}", text, re.S)
    if not m:
        return None
    try:
        val = json.loads(m.group(0))
    except (ValueError, TypeError):
        try:
            val = json.loads(m.group(0).replace("'", '"'))
        except (ValueError, TypeError):
            return None
    return val if isinstance(val, dict) else None


def _from_json(obj: dict, reply: StepReply) -> None:
    for key, val in obj.items():
        k = re.sub(r"[^a-z]", "", str(key).lower())
        if "description" in k and reply.description is None and val is not None:
            reply.description = str(val).strip() or None
        elif ("percent" in k or "progress" in k or "completion" in k) and reply.progress is None:
            reply.progress = parse_percentage(val)
        elif ("needsto" in k or "newsubtask" in k or "nextsubtask" in k) and val:
            if isinstance(val, list):
                reply.plan = [str(v) for v in val if str(v).strip()]
                reply.new_subtask = reply.plan[0] if reply.plan else None
            else:
                reply.new_subtask = _strip_subtask(str(val)) or None
        elif k in ("taskcomplete", "complete", "done") and val is True:
            reply.task_complete = True


def parse_step(text: object) -> StepReply:
    """Parse a ROVER reply: description + (progress and [next-frame] | new subtask | complete)."""
    reply = StepReply()
    t = clean(text)
    if not t.strip():
        return reply
    obj = _json_object(t)
    if obj is not None:
        _from_json(obj, reply)
    desc_lines: list[str] | None = None
    for raw in t.split("\n"):
        line = raw.strip()
        if not line:
            desc_lines = None
            continue
        if _NEXT.search(line):
            reply.next_frame = True
        if m := _PLAN.match(line):
            items = _split_list(m.group(1))
            if items:
                reply.plan = items
            desc_lines = None
        elif m := _NEEDS_TO.search(line):
            rest = m.group(1).strip()
            if rest.startswith("["):
                items = _split_list(rest)
                if items:
                    reply.plan = reply.plan or items
                    reply.new_subtask = items[0]
            elif _strip_subtask(rest):
                reply.new_subtask = _strip_subtask(rest)
            desc_lines = None
        elif m := _DESC.match(line):
            reply.description = m.group(1).strip().strip("\"'") or reply.description
            desc_lines = [reply.description] if reply.description else []
        elif (m := _PCT_LINE.match(line)) and (v := parse_percentage(m.group(1))) is not None:
            reply.progress = v
            desc_lines = None
        elif desc_lines is not None and not _NEXT.fullmatch(line):
            desc_lines.append(line)
            reply.description = " ".join(desc_lines)
    if reply.new_subtask is None and reply.plan:
        reply.new_subtask = reply.plan[0]
    if reply.progress is None and reply.new_subtask is None:
        # compact answers: "45% [next-frame]" or a lone number
        m = re.search(rf"({_NUM})\s*(?:%|percent)", t, re.I)
        if m:
            reply.progress = parse_percentage(m.group(1))
    if _COMPLETE.search(t) and reply.progress is None and reply.new_subtask is None:
        reply.task_complete = True
    if reply.description:
        reply.description = _NEXT.sub("", reply.description).strip() or None
    return reply


def parse_frames(text: object) -> dict[int, FrameAnswer]:
    """Per-frame answers from a multi-frame reply ("Frame k: ... Task completion: N%").

    Keys are the frame labels the model used; values may miss a description or a number.
    JSON lists of objects with a frame number are accepted too.
    """
    t = clean(text)
    out: dict[int, FrameAnswer] = {}
    if not t.strip():
        return out
    m = re.search(r"\[.*\]", t, re.S)
    if m:
        try:
            items = json.loads(m.group(0))
        except (ValueError, TypeError):
            items = None
        if isinstance(items, list):
            for item in items:
                if not isinstance(item, dict):
                    continue
                label = next((v for k, v in item.items() if "frame" in str(k).lower()), None)
                num = parse_percentage(label) if not isinstance(label, bool) else None
                if num is None:
                    continue
                reply = StepReply()
                _from_json({k: v for k, v in item.items() if "frame" != str(k).lower()}, reply)
                out[int(num)] = FrameAnswer(reply.description, reply.progress)
            if out:
                return out
    current: int | None = None
    block: list[str] = []

    def flush() -> None:
        if current is None:
            return
        body = "\n".join(block)
        d, p = _FAST_DESC.search(body), _FAST_PCT.search(body)
        if d and p and d.end() <= p.start():
            ans = FrameAnswer(d.group(1).strip() or None, parse_percentage(p.group(1)))
        else:
            ans = parse_frame(body)
        prev = out.get(current)
        if prev is None or (prev.progress is None and ans.progress is not None):
            out[current] = ans

    for raw in t.split("\n"):
        line = raw.strip()
        hm = _FRAME_HEADER.match(line)
        if hm and not _DESC.match(line):
            flush()
            current, block = int(hm.group(1)), [hm.group(2)]
        elif current is not None:
            block.append(line)
    flush()
    return out


def parse_frame(text: object) -> FrameAnswer:
    """One frame's description and progress (missing parts stay None)."""
    r = parse_step(text)
    if r.progress is None:
        m = re.search(rf"({_NUM})\s*(?:%|percent)", clean(text), re.I)
        if m:
            r.progress = parse_percentage(m.group(1))
    desc = r.description
    if desc is None:
        rest = [
            ln.strip()
            for ln in clean(text).split("\n")
            if ln.strip() and not _PCT_LINE.match(ln.strip()) and not _NEXT.search(ln)
        ]
        desc = " ".join(rest).strip() or None
        if desc and parse_percentage(desc) is not None and len(desc) < 12:
            desc = None
    return FrameAnswer(description=desc, progress=r.progress)
