"""Reading checkable claims out of a frame description (used by the rule judge and QA).

A description such as "The gripper is closed around the soda can, lifting it off the
table; it is not yet in the bin." makes claims about things the simulator records
(`FrameFacts`): gripper open/closed, what the gripper touches and holds, whether an object
is lifted, where it is, how far a door/drawer/knob is open or turned, whether a button is
pressed. Models write these in endless ways, so the reading is by clause, not by sentence
template:

1. markdown, "Frame description:" labels and "Gripper: open" lines become plain sentences;
2. sentences split into clauses at commas, semicolons, "and", "while", "but", and before
   "which"; a clause without a noun of its own continues the previous one;
3. in each clause, mentions are found (gripper words, robot words, objects by head noun
   with their modifiers, places such as bins and the table); "it" / "which" / "its" stand
   for the last object mentioned;
4. detectors look for the words of each claim family around those mentions, with the
   clause's negation ("not", "n't", "no longer", "without", "yet to", "no") and skipping
   intentions ("about to grasp", "preparing to press", "moving toward").

Anything else — motion, intention, appearance — yields no claim and is inconclusive.
"""

from __future__ import annotations

import re

from rover.eval.claim_detectors import _PARTS, Claim, ClaimKind, Mention, clause_claims
from rover.eval.claim_names import names_match, normalise_name  # noqa: F401 - re-exported

__all__ = ["Claim", "ClaimKind", "extract_claims", "names_match", "normalise_name"]

_MODS = (
    r"red|green|blue|yellow|round|square|soda|drink|coke|cylindrical|small|large|milk|"
    r"cereal|stove|push|door|drawer|wooden|metal|white|ring-shaped|square-shaped|target|goal|"
    r"start|starting|original|initial|correct|destination|microwave|cabinet|second|first"
)
_HEADS = (
    r"cans?|cubes?|blocks?|milk|carton|bread|loaf|cereal|box|nut|ring|peg|post|rod|door|"
    r"drawer|knob|dial|button|handle|bins?|table|tabletop|surface|counter|ground|floor|"
    r"cylinder|object|item"
)
_PLACES = {"bin", "bins", "table", "tabletop", "surface", "counter", "ground", "floor"}
_MENTION = re.compile(
    rf"\b(?P<grip>gripper'?s?|fingers?|jaws|claw|end[\s-]effector|hand)\b"
    rf"|\b(?P<robot>robot(?:'s)?|arm|panda|manipulator)\b"
    rf"|\b(?P<pron>it|which|its)\b"
    rf"|\b(?P<one>(?:red|green|blue|yellow|round|square|other|left|right)\s+one)\b"
    rf"|\b(?P<obj>(?:(?:{_MODS})\s+){{0,2}}(?:{_HEADS})(?:\s+\d+)?)\b",
    re.I,
)
_LABEL = re.compile(
    r"^\s*(?:frame\s+description|description|observation|observations|scene\s+state|"
    r"key\s+observations|scene|state|summary|analysis)\s*:\s*",
    re.I,
)
_KEY_VALUE = re.compile(r"^\s*(?P<k>[a-z][\w' -]{0,30}?)\s*:\s*(?P<v>.+)$", re.I)
_SENTENCE = re.compile(r"(?<=[.!?;])\s+|\n+")
_CLAUSE = re.compile(
    r"\s*[,;:]\s*(?:and\s+|while\s+|but\s+|then\s+)?|\s+(?:and|while|but|whereas|though)\s+"
    r"|\s+(?=which\b)",
    re.I,
)


def _plain(description: str) -> list[str]:
    """Markdown stripped, labels dropped, "Gripper: open" lines made sentences."""
    text = re.sub(r"```\w*|\*\*|__|`", "", description)
    text = re.sub(r"between\s+the\s+(?:gripper|robot|fingers)\s+and\s+", "with ", text, flags=re.I)
    lines = []
    for line in text.splitlines():
        line = re.sub(r"^\s*(?:#+|[-*•]|\d+[.)])\s+", "", line)
        line = _LABEL.sub("", line).strip()
        if not line:
            continue
        kv = _KEY_VALUE.match(line)
        if kv and len(kv.group("k").split()) <= 3:
            key, value = kv.group("k").strip(), kv.group("v").strip()
            if _MENTION.search(key) and not re.match(r"(?:the|a|an)\b", value, re.I):
                line = f"the {key} is {value}"
            else:
                line = value
        lines.append(line)
    return [s for line in lines for s in _SENTENCE.split(line) if s.strip()]


class _Reader:
    """Carries the last object mentioned across clauses, for pronouns."""

    def __init__(self) -> None:
        self.last_obj: str | None = None
        self.last_part: str | None = None

    def mentions(self, clause: str) -> list[Mention]:
        out = []
        for m in _MENTION.finditer(clause):
            if m.group("grip"):
                out.append(Mention("grip", m.group(0), m.start(), m.end()))
            elif m.group("robot"):
                out.append(Mention("robot", m.group(0), m.start(), m.end()))
            elif m.group("one"):  # "the green one": the head of the last object named
                if self.last_obj:
                    head = self.last_obj.split()[-1]
                    text = f"{m.group('one').split()[0].lower()} {head}"
                    out.append(Mention("obj", text, m.start(), m.end()))
            elif m.group("pron"):
                if m.group(0).lower() == "its":
                    nxt = clause[m.end() : m.end() + 12].lower()
                    if not nxt.strip().startswith("handle"):
                        continue  # "its gripper", "its position": not an object
                    ref = self.last_part or self.last_obj
                else:
                    ref = self.last_obj
                if ref:
                    out.append(Mention("obj", ref, m.start(), m.end()))
            else:
                text = normalise_name(m.group("obj"))
                head = text.split()[-1] if not text.split()[-1].isdigit() else text.split()[-2]
                if head == "handle" and re.search(r"'s\s+$", clause[: m.start()]):
                    continue  # "the nut's handle": the nut, already mentioned
                kind = "place" if head in _PLACES else "obj"
                if head in ("object", "item"):
                    if not self.last_obj:
                        continue
                    text = self.last_obj
                out.append(Mention(kind, text, m.start(), m.end()))
            last = out[-1] if out else None
            if last is not None and last.kind == "obj" and last.start == m.start():
                self.last_obj = last.text
                if any(p in last.text.split() for p in _PARTS):
                    self.last_part = last.text
        return out


def extract_claims(description: str | None) -> list[Claim]:
    """Every checkable claim in a description, in reading order."""
    if not description:
        return []
    reader = _Reader()
    claims: list[Claim] = []
    for sentence in _plain(description):
        carry: str | None = None  # the subject a noun-less clause continues
        for clause in _CLAUSE.split(sentence):
            clause = clause.strip(" .!?")
            if not clause:
                continue
            ms = reader.mentions(clause)
            if not ms and carry:
                clause_subject = carry
                ms = [Mention("obj" if carry != "gripper" else "grip", carry, -1, -1)]
            else:
                clause_subject = None
            found = clause_claims(clause, ms)
            claims.extend(found)
            head = ms[0] if ms else None
            if head is not None:
                carry = (
                    "gripper"
                    if head.kind == "grip"
                    else (head.text if head.kind == "obj" else carry)
                )
            if clause_subject:
                carry = clause_subject
    return claims
