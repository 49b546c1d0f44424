"""The answer format as a small line grammar: what each line of a model reply says.

The prompts ask for labelled fields ("Frame description: …", "Subtask completion
percentage: N%", "[next-frame]", "New subtasks: [...]", "The robot needs to: …").
Models write them with markdown (bold, italic, headings, bullets), in any case, with or
without the colon, one field per line or several on one line, or with the value on the
line below a heading. This module turns a reply into `Fields` in one pass over its lines.

Rules that keep prose from being misread:
- a label counts at the start of a line (after markup) or, inline, after a sentence end;
- "The robot needs to" and "New subtasks" count only with their colon, so a description
  such as "the robot needs to lift it next" never starts a subtask;
- a percentage is read from a progress label, or, when there is none, from text outside
  the description ("The drawer is 40% open." stays a description);
- subtask names end at the sentence end.

Every pattern is anchored or starts with a literal word and uses bounded whitespace, so
the work is linear in the reply's length; replies are cut at `MAX_PARSE_CHARS` first.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass

MAX_PARSE_CHARS = 65536  # longer replies are parsed from their first 64 KB only
MAX_PARSE_LINES = 2000  # ... and their first 2,000 lines (a 240-frame GVL reply has ~1,000)
_MAX_LABELS = 12  # fields read from one line (a real one-line answer has 2 or 3)
MAX_ITEMS = 64  # entries read from one plan (ROVER keeps at most 8 subtasks per line)

# a number with an optional sign; whitespace bounded so a search never scans ahead
NUM = r"(?<![\d.,])[-+−–]?[ \t]{0,2}\d{1,12}(?:[.,]\d{1,12})?"
_NUMBER = re.compile(NUM)
_PCT_VALUE = re.compile(
    r"[~≈]?[ \t]{0,3}"
    r"(?:(?:about|approximately|approx\.?|around|roughly|nearly|estimated)[ \t]{1,3})?"
    rf"({NUM})[ \t]{{0,2}}(%|percent\b)?",
    re.I,
)
_PCT_ANY = re.compile(rf"({NUM})[ \t]{{0,2}}(?:%|percent\b)", re.I)
# a percentage closing a sentence of free text: "…, 55%", "… (about 10%)."
_PCT_TAIL = re.compile(
    rf"[ \t]{{0,3}}[,;:(\-–—]?[ \t]{{0,3}}(?:about[ \t]+|~)?{NUM}"
    r"[ \t]{0,2}(?:%|percent)[ \t]*\)?[.!]?$",
    re.I,
)
_NEXT = re.compile(r"\[[ \t]{0,3}next[ \t_-]{0,3}frame[ \t]{0,3}\]", re.I)
_LEAD = re.compile(r"#{1,6}[ \t]*|>[ \t]*|(?:[-*•+]|\d{1,3}[.)])[ \t]+")
_LABEL = re.compile(
    r"\b(?:"
    r"(?P<desc>(?:current[ \t]+|final[ \t]+)?frame[ \t]+description|description)"
    r"|(?P<pct>(?:sub[ \t]?-?[ \t]?task[ \t]+|task[ \t]+)?(?:completion|progress)"
    r"(?:[ \t]+(?:percentage|percent|value|estimate|level))?(?:[ \t]*\(%\))?)"
    r"|(?P<needs>the[ \t]+robot[ \t]+needs[ \t]+to)"
    r"|(?P<plan>new[ \t]+sub[ \t]?-?[ \t]?tasks|sub[ \t]?-?[ \t]?task[ \t]+plan|subtasks|plan)"
    r"|(?P<sub>(?:new|next)[ \t]+sub[ \t]?-?[ \t]?task)"
    r")(?![A-Za-z])(?P<sep>[ \t]*(?:[:=]|[-–—](?![\d.]))[ \t]*|[ \t]*)",
    re.I,
)
_SENTENCE_END = re.compile(r"[.!?;](?:[ \t]|$)")
_COMPLETE = re.compile(
    r"^(?:the[ \t]+)?(?:whole[ \t]+|entire[ \t]+|overall[ \t]+)?(?:sub[ \t]?-?[ \t]?)?task"
    r"[ \t]+(?:is[ \t]+)?(?:now[ \t]+)?(?:complete|completed|finished|done)\b[.!]*$",
    re.I,
)
QUOTES = "\"'“”‘’`"


@dataclass
class Line:
    """One reply line with its markup removed."""

    text: str
    item: bool = False  # a bullet or numbered-list entry
    heading: bool = False


def cap(text: object) -> str:
    """The part of a reply the parsers read: its first 64 KB and 2,000 lines ('' if no str)."""
    if not isinstance(text, str):
        return ""
    text = text[:MAX_PARSE_CHARS]
    if text.count("\n") >= MAX_PARSE_LINES:
        text = "\n".join(text.split("\n", MAX_PARSE_LINES)[:MAX_PARSE_LINES])
    return text


def capped(text: object) -> bool:
    """Whether `cap` cut this reply."""
    return isinstance(text, str) and (
        len(text) > MAX_PARSE_CHARS or text.count("\n", 0, MAX_PARSE_CHARS) >= MAX_PARSE_LINES
    )


def strip_markup(raw: str) -> Line | None:
    """A line without heading/quote/bullet prefixes and emphasis; None for code fences."""
    s = raw.strip()
    if not s or s[0].isalpha() and not ("*" in s or "_" in s or "`" in s):
        return Line(s)  # the common case: plain text, nothing to remove
    if s.startswith("```"):
        return None
    item = heading = False
    while True:
        m = _LEAD.match(s)
        if not m:
            break
        tok = m.group(0)
        heading = heading or tok.startswith("#")
        item = item or not tok.startswith(("#", ">"))
        s = s[m.end() :]
    s = s.replace("**", "").replace("__", "").replace("`", "").replace("*", "").strip()
    return Line(s, item, heading)


def lines_of(text: str) -> list[Line | None]:
    """Markup-free lines (None marks a code fence)."""
    return [strip_markup(r) for r in text.replace("\r\n", "\n").replace("\r", "\n").split("\n")]


def parse_percentage(value: object) -> float | None:
    """The first finite number in `value` ("45%", "-10.5 %", "about 120 percent", 0.5)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        v = float(value)
        return v if math.isfinite(v) else None
    if not isinstance(value, str):
        return None
    m = _NUMBER.search(value[:MAX_PARSE_CHARS])
    return _to_float(m.group(0)) if m else None


_BLANKS = re.compile(r"[ \t]")


def _to_float(s: str) -> float | None:
    s = _BLANKS.sub("", s).replace("−", "-").replace("–", "-").replace(",", ".")
    try:
        v = float(s)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def leading_percentage(value: str) -> float | None:
    """A number at the start of a field's value ("45%", "approximately 45 %")."""
    m = _PCT_VALUE.match(value.strip())
    return _to_float(m.group(1)) if m else None


def drop_percentage_tail(text: str) -> str:
    """Free text without a closing percentage ("The gripper is open. 10%" -> first part)."""
    if not _ends_with_percent(text):
        return text
    m = _PCT_TAIL.search(text[-80:])
    return text[: len(text) - len(text[-80:]) + m.start()].strip() if m else text


def _has_percent(text: str) -> bool:
    return "%" in text or "percent" in text.lower()


def _ends_with_percent(text: str) -> bool:
    t = text.rstrip(" \t.!)")
    return t.endswith("%") or t[-7:].lower() == "percent"


def tail_percentage(text: str) -> float | None:
    """The percentage closing a piece of free text ("The drawer is 40% open. 12%" -> 12)."""
    if not _ends_with_percent(text):
        return None
    m = _PCT_TAIL.search(text[-80:])
    return any_percentage(m.group(0)) if m else None


def any_percentage(text: str) -> float | None:
    """The first "N%" / "N percent" in free text."""
    if not _has_percent(text):
        return None
    m = _PCT_ANY.search(text)
    return _to_float(m.group(1)) if m else None


def subtask_name(s: str) -> str:
    """A subtask as the model named it: quotes, brackets and trailing prose removed."""
    s = _NEXT.sub("", s).strip().strip(QUOTES + "[]{}()").strip()
    m = _SENTENCE_END.search(s)
    if m:
        s = s[: m.start()]
    return s.strip().rstrip(".").strip().strip(QUOTES).strip()


def split_list(s: str) -> list[str]:
    """Items of a list written as JSON, Python (apostrophes inside items kept) or CSV."""
    s = s.strip().rstrip(".").strip()
    if s.startswith("["):
        try:
            val = json.loads(s)
            if isinstance(val, list):
                return [n for n in (subtask_name(str(v)) for v in val) if n]
        except ValueError:
            pass
        s = s[1:]
        end = s.rfind("]")
        s = s[:end] if end >= 0 else s
    s = s.strip()
    if s and s[0] in QUOTES:
        # items are quote…quote separated by commas: split only at quote-comma-quote
        parts = re.split(
            rf"[{QUOTES}][ \t]{{0,3}}[,;][ \t\n]{{0,8}}[{QUOTES}]", s, maxsplit=MAX_ITEMS
        )
    else:
        parts = re.split(r"[;,]", s, maxsplit=MAX_ITEMS)
    parts = parts[:MAX_ITEMS]
    return [n for n in (subtask_name(p) for p in parts) if n]


def _label_ok(line: str, m: re.Match[str], kind: str) -> bool:
    """Whether a label match is a field label rather than a word in prose."""
    sep, rest = m.group("sep"), line[m.end() : m.end() + 40].strip()  # bounded: linear
    colon = any(c in sep for c in ":=-–—")
    at_start = m.start() == 0
    if not at_start:
        i = m.start() - 1
        while i > 0 and line[i] in " \t":
            i -= 1
        if line[i] not in ".!?;|)]%":
            return False  # inside a sentence: prose, not a label
        if kind == "desc" and m.group("desc").lower() == "description":
            return False
    if kind == "plan" and at_start and not rest:
        return True  # "### New subtasks" as a heading over a list
    if kind in ("needs", "plan", "sub"):
        return colon  # the decomposition markers count only with their colon
    if kind == "pct":
        number = leading_percentage(rest) is not None
        return (colon or at_start) and number or at_start and not rest
    if kind == "desc" and at_start and m.group("desc").lower() != "description":
        return True  # "Frame description" opens a description, colon or not
    return colon or at_start and not rest  # a description label, or its heading


_KEYWORDS = ("descr", "complet", "progress", "needs", "plan", "task")


def labels(line: str) -> list[tuple[str, int, int]]:
    """(kind, label start, value start) of every field label on one line."""
    low = line.lower()
    if not any(k in low for k in _KEYWORDS):
        return []  # the common case for prose lines: no label word at all
    out = []
    for m in _LABEL.finditer(line):
        kind = next(k for k in ("desc", "pct", "needs", "plan", "sub") if m.group(k))
        if _label_ok(line, m, kind):
            out.append((kind, m.start(), m.end()))
            if len(out) >= _MAX_LABELS:
                break
    return out


def split_complete(desc: str) -> tuple[str, bool]:
    """Remove a trailing "Task complete." sentence from a description."""
    d = desc.strip()
    if _COMPLETE.match(d):
        return "", True
    cut = max(d.rfind(". ", 0, len(d) - 1), d.rfind("! ", 0, len(d) - 1))
    if cut >= 0 and _COMPLETE.match(d[cut + 2 :].strip()):
        return d[: cut + 1].strip(), True
    return d, False


def is_complete(line: str) -> bool:
    return bool(_COMPLETE.match(line.strip().strip(QUOTES)))


def has_next(line: str) -> tuple[str, bool]:
    """The line without "[next-frame]" markers, and whether it had one."""
    if "[" not in line:
        return line, False
    new = _NEXT.sub("", line)
    return new.strip(), new != line
