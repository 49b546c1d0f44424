"""Reading model replies: tolerant of prose, markdown and JSON, and never raising.

Real VLMs rarely follow the answer format to the letter: they bold or italicise the
labels, write headings with the value underneath, answer in JSON or markdown tables, put
every field on one line, write "45.5 %", "-10%" or "about 120 percent", or add chatter.
The line grammar (`reply_grammar`, `reply_fields`) reads the fields; this module turns
them into what each method branches on. Every function returns `None` (or an empty
result) for a reply it cannot use instead of raising, so the methods can re-ask once with
a format reminder and then record a parse failure, carrying the last value forward.

Work is linear in the reply's length, and only a reply's first 64 KB and 2,000 lines are
read (`reply_capped` says when a reply was longer; the trace records it).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from typing import Any

from rover.methods.reply_fields import Fields, read_fields
from rover.methods.reply_grammar import (
    MAX_PARSE_CHARS,
    Line,
    any_percentage,
    cap,
    capped,
    drop_percentage_tail,
    leading_percentage,
    lines_of,
    parse_percentage,
    split_complete,
    subtask_name,
    tail_percentage,
)

__all__ = [
    "MAX_PARSE_CHARS",
    "FrameAnswer",
    "StepReply",
    "parse_frame",
    "parse_frames",
    "parse_percentage",
    "parse_step",
    "reply_capped",
]

_FRAME_HEADER = re.compile(r"frame[ \t]{0,3}#?[ \t]{0,3}(\d{1,6})(?![\d.,]\d)(?![ \t]*%)", re.I)
_HEADER_SEP = re.compile(r"[ \t]*(?:\([^)]{0,40}\))?[ \t]*[:.\-–—)]?[ \t]*")
_ANCHOR = re.compile(r"(?:initial[ \t]+robot[ \t]+scene|anchor)\b", re.I)


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


def reply_capped(text: object) -> bool:
    """Whether a reply is longer than what the parsers read (64 KB, 4,000 lines)."""
    return capped(text)


# -- JSON -------------------------------------------------------------------------------


def _json_value(text: str, opener: str) -> Any:
    """The JSON value starting at the first `opener` ('{' or '['), or None (linear)."""
    start = text.find(opener)
    if start < 0:
        return None
    decoder = json.JSONDecoder()
    for candidate in (text, text.replace("'", '"')):
        try:
            return decoder.raw_decode(candidate, candidate.find(opener))[0]
        except ValueError:
            continue
    return None


def _key(k: object) -> str:
    return re.sub(r"[^a-z]", "", str(k).lower())


def _from_json(obj: dict, f: Fields) -> None:
    for key, val in obj.items():
        k = _key(key)
        if "description" in k and f.description is None and isinstance(val, str | int | float):
            f.description = str(val).strip() or None
        elif ("percent" in k or "progress" in k or "completion" in k) and f.progress is None:
            f.progress = parse_percentage(val) if not isinstance(val, str) else None
            if isinstance(val, str):
                f.progress = leading_percentage(val) or parse_percentage(val)
        elif k in ("newsubtasks", "subtasks", "plan") and isinstance(val, list):
            f.plan = [n for n in (subtask_name(str(v)) for v in val) if n]
        elif "needsto" in k or k in ("newsubtask", "nextsubtask", "subtask"):
            if isinstance(val, list):
                f.plan = f.plan or [n for n in (subtask_name(str(v)) for v in val) if n]
            elif isinstance(val, str) and subtask_name(val):
                f.new_subtask = subtask_name(val)
        elif k in ("taskcomplete", "complete", "done", "subtaskcomplete") and val is True:
            f.task_complete = True
        elif k == "nextframe" and val:
            f.next_frame = True


# -- ROVER steps ------------------------------------------------------------------------


def _loose_text(f: Fields, used_pct: bool) -> str | None:
    """Unlabelled prose as a description: chatter and the sentence giving the % dropped."""
    keep = []
    for s in f.loose:
        if used_pct and (t := drop_percentage_tail(s)) != s:
            s = t  # "The gripper is open. 10%": the closing percentage was the answer
        elif used_pct and any_percentage(s) is not None:
            continue  # "I'd say roughly 30% done.": the sentence was the answer
        if not s or s.endswith(":"):
            continue
        if leading_percentage(s) is not None and len(s) < 12:
            continue
        keep.append(s)
    text = " ".join(keep).strip()
    return text or None


def loose_percentage(f: Fields) -> float | None:
    """Progress from unlabelled text: a closing "… 12%" first, else the first "N%"."""
    for s in f.loose:
        if (v := tail_percentage(s)) is not None:
            return v
    for s in f.loose:
        if (v := any_percentage(s)) is not None:
            return v
    return None


def _fields(text: object) -> Fields:
    t = cap(text)
    if not t.strip():
        return Fields()
    f = read_fields(lines_of(t))
    if "{" in t and (f.progress is None and f.new_subtask is None or f.description is None):
        obj = _json_value(t, "{")
        if isinstance(obj, dict):
            j = Fields()
            _from_json(obj, j)
            if j.progress is not None or j.new_subtask or j.plan or j.description:
                f = j
                if f.new_subtask is None and f.plan:
                    f.new_subtask = f.plan[0]
    return f


def parse_step(text: object) -> StepReply:
    """Parse a ROVER reply: description + (progress and [next-frame] | new subtask | complete).

    When a reply gives both a progress value and a new subtask, the progress wins (as in
    the public reference code): a model that reports progress is still on its subtask.
    """
    f = _fields(text)
    used_pct = False
    if f.progress is None and f.new_subtask is None:
        f.progress = loose_percentage(f)  # compact answers: "45% [next-frame]", "30% done"
        used_pct = f.progress is not None
    if f.description is None:
        f.description = _loose_text(f, used_pct)
        if f.description:
            f.description, done = split_complete(f.description)
            f.task_complete = f.task_complete or done
            f.description = f.description or None
    new = f.new_subtask if f.progress is None else None
    complete = f.task_complete and f.progress is None and new is None
    return StepReply(f.description, f.progress, f.next_frame, new, list(f.plan), complete)


# -- per-frame replies (GVL, concat) ----------------------------------------------------


def parse_frame(text: object) -> FrameAnswer:
    """One frame's description and progress (missing parts stay None)."""
    r = parse_step(text)
    return FrameAnswer(r.description, r.progress)


def _block(lines: list[Line | None]) -> FrameAnswer:
    f = read_fields(lines)
    used = False
    if f.progress is None:
        f.progress = loose_percentage(f)
        used = f.progress is not None
    desc = f.description or _loose_text(f, used)
    if desc:
        desc = split_complete(desc)[0] or None
    return FrameAnswer(desc, f.progress)


def _table(rows: list[str], out: dict[int, FrameAnswer]) -> None:
    """A markdown table: a header naming the frame/description/percentage columns."""
    cols = {"frame": 0, "desc": 1, "pct": 2}
    for row in rows:
        cells = [c.strip().replace("*", "") for c in row.strip().strip("|").split("|")]
        low = [c.lower() for c in cells]
        if all(set(c) <= set("-: ") for c in cells):
            continue  # the |---|---| separator
        if any("frame" in c or "description" in c or "complet" in c for c in low) and not any(
            c.isdigit() for c in low
        ):
            cols = {}
            for i, c in enumerate(low):
                if "desc" in c:
                    cols["desc"] = i
                elif "%" in c or "complet" in c or "progress" in c or "percent" in c:
                    cols["pct"] = i
                elif "frame" in c:
                    cols.setdefault("frame", i)
            continue
        got = {name: cells[i] for name, i in cols.items() if i < len(cells)}
        label = re.match(r"\D{0,10}(\d{1,6})", got.get("frame", ""))
        if not label:
            continue
        pct = got.get("pct", "")
        ans = FrameAnswer(got.get("desc") or None, leading_percentage(pct) or parse_percentage(pct))
        k = int(label.group(1))
        if k not in out or (out[k].progress is None and ans.progress is not None):
            out[k] = ans


def _json_frames(t: str, out: dict[int, FrameAnswer]) -> None:
    items = _json_value(t, "[")
    if not isinstance(items, list):
        obj = _json_value(t, "{")
        if isinstance(obj, dict):
            items = next((v for v in obj.values() if isinstance(v, list)), None)
    for item in items if isinstance(items, list) else []:
        if not isinstance(item, dict):
            continue
        label = next((v for k, v in item.items() if _key(k) in ("frame", "frameindex")), None)
        num = parse_percentage(label)
        if num is None:
            continue
        f = Fields()
        _from_json({k: v for k, v in item.items() if _key(k) != "frame"}, f)
        out[int(num)] = FrameAnswer(f.description, f.progress)


def parse_frames(text: object) -> dict[int, FrameAnswer]:
    """Per-frame answers from a multi-frame reply ("Frame k: ... Task completion: N%").

    Keys are the frame labels the model used; values may miss a description or a number.
    Blocks headed "Frame k" (bold, heading, "Frame k: …" inline), markdown tables with a
    frame column and JSON lists of objects with a frame number are all accepted.
    """
    t = cap(text)
    out: dict[int, FrameAnswer] = {}
    if not t.strip():
        return out
    if "[" in t and "{" in t:
        _json_frames(t, out)
        if out:
            return out
    current: int | None = None
    block: list[Line | None] = []
    table: list[str] = []

    def flush() -> None:
        if current is not None:
            ans = _block(block)
            prev = out.get(current)
            if prev is None or (prev.progress is None and ans.progress is not None):
                out[current] = ans

    for line in lines_of(t):
        if line is not None and line.text.startswith("|"):
            table.append(line.text)
            continue
        hm = _FRAME_HEADER.match(line.text) if line is not None else None
        if hm and not line.text.lower().startswith("frame description"):
            flush()
            rest = line.text[hm.end() :]
            rest = rest[_HEADER_SEP.match(rest).end() :]  # type: ignore[union-attr]
            current, block = int(hm.group(1)), [Line(rest)]
        elif line is not None and _ANCHOR.match(line.text):
            flush()
            current, block = None, []
        elif current is not None:
            block.append(line)
    flush()
    if table:
        _table(table, out)
    return out
