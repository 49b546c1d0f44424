"""One pass over a reply's lines: which field each line states (see `reply_grammar`).

The reader keeps a little state between lines: a label whose value is on the next line
(heading style), a description running over several lines until a blank line or the
next label, a plan given as a bullet list or as a bracketed list spread over lines.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rover.methods.reply_grammar import (
    MAX_ITEMS,
    QUOTES,
    Line,
    has_next,
    is_complete,
    labels,
    leading_percentage,
    split_complete,
    split_list,
    subtask_name,
)


@dataclass
class Fields:
    """What a reply (or one frame's block of it) said, field by field."""

    description: str | None = None
    progress: float | None = None
    next_frame: bool = False
    new_subtask: str | None = None
    plan: list[str] = field(default_factory=list)
    task_complete: bool = False
    loose: list[str] = field(default_factory=list)  # unlabelled text, in order


class _Reader:
    """The state of one pass over a reply's lines (see `read_fields`)."""

    def __init__(self) -> None:
        self.f = Fields()
        self.desc: list[str] | None = None  # description lines being collected
        self.desc_done: list[str] = []  # the first description, once closed
        self.pending: str | None = None  # a label whose value is on a following line
        self.items: list[str] | None = None  # plan entries given as a bullet list
        self.bracket: list[str] | None = None  # a [...] plan spread over lines

    def close(self) -> None:
        if self.desc is not None and not self.desc_done:
            self.desc_done = self.desc
        self.desc = None
        if self.items is not None:
            if self.items and not self.f.plan:
                self.f.plan = self.items
            self.items = None

    def subtask(self, value: str) -> None:
        if value.startswith("["):
            if "]" not in value:
                self.bracket = [value]
                return
            names = split_list(value)
            self.f.plan = self.f.plan or names
            value = names[0] if names else ""
        name = subtask_name(value)
        if name and self.f.new_subtask is None:
            self.f.new_subtask = name

    def plan(self, value: str) -> None:
        if value.startswith("[") and "]" not in value:
            self.bracket = [value]
        elif value:
            self.f.plan = self.f.plan or split_list(value)
        else:
            self.items = []

    def field(self, kind: str, value: str, last: bool) -> None:
        if not value:
            self.pending = kind
            if kind == "plan":
                self.items = []
            return
        if kind == "desc":
            self.close()
            if last:
                self.desc = [value]
            elif not self.desc_done:
                self.desc_done = [value]
        elif kind == "pct":
            if self.f.progress is None:
                self.f.progress = leading_percentage(value)
        elif kind in ("needs", "sub"):
            self.subtask(value)
        else:
            self.plan(value)

    def value_line(self, line: Line, s: str) -> None:
        """The value of a label written alone on the line above (heading style)."""
        kind, self.pending = self.pending, None
        if kind in ("needs", "sub", "plan") and line.item:
            self.items = [subtask_name(s)]
            if kind != "plan":
                self.f.new_subtask = self.f.new_subtask or self.items[0]
        elif kind == "plan":
            self.items = None
            self.plan(s)
        else:
            self.field(kind or "desc", s, True)

    def line(self, line: Line | None) -> None:
        if line is None:
            return
        s, nxt = has_next(line.text)
        self.f.next_frame = self.f.next_frame or nxt
        if self.bracket is not None:
            self.bracket.append(s)
            if "]" in s or len(self.bracket) >= MAX_ITEMS:
                value, self.bracket = " ".join(self.bracket), None
                self.f.plan = self.f.plan or split_list(value)
            return
        if not s:
            if self.pending is None and not nxt:
                self.close()
            return
        found = labels(s)
        if self.items is not None:
            if line.item and not found:
                if len(self.items) < MAX_ITEMS:
                    self.items.append(subtask_name(s))
                return
            if self.pending == "plan" and not found:
                self.value_line(line, s)
                return
            self.pending = None
            self.close()
        if not found:
            if self.pending is not None:
                self.value_line(line, s)
            elif is_complete(s):
                self.f.task_complete = True
            elif self.desc is not None:
                self.desc.append(s)
            else:
                self.f.loose.append(s)
            return
        self.pending = None
        self.close()
        if found[0][1] > 0:
            self.f.loose.append(s[: found[0][1]].strip())
        for i, (kind, _start, vstart) in enumerate(found):
            end = found[i + 1][1] if i + 1 < len(found) else len(s)
            self.field(kind, s[vstart:end].strip(), i + 1 == len(found))

    def finish(self) -> Fields:
        if self.bracket is not None:
            self.f.plan = self.f.plan or split_list(" ".join(self.bracket))
        self.close()
        f = self.f
        if self.desc_done:
            desc, done = split_complete(" ".join(self.desc_done))
            f.task_complete = f.task_complete or done
            f.description = desc.strip().strip(QUOTES).strip() or None
        if f.new_subtask is None and f.plan:
            f.new_subtask = f.plan[0]
        return f


def read_fields(lines: list[Line | None]) -> Fields:
    """One pass over a reply's lines: the fields it states, plus its unlabelled text."""
    r = _Reader()
    for line in lines:
        r.line(line)
    return r.finish()
