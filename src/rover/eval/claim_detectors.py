"""The claim detectors: which words in a clause make which claim (see `rover.eval.claims`).

A clause arrives with its mentions (gripper, robot, objects, places; pronouns already
resolved); each detector looks for the words of one claim family around them, applies the
clause's negation and skips intentions. Kept apart from the clause reading so each module
stays readable; `rover.eval.claims.extract_claims` is the entry point.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal

ClaimKind = Literal[
    "gripper",
    "holding",
    "holding_any",
    "contact",
    "contact_any",
    "lifted",
    "inside",
    "on",
    "at_start",
    "articulation",
    "articulation_pct",
    "pressed",
]


@dataclass(frozen=True)
class Claim:
    """One statement about the scene: `kind`, its subject, the asserted value, the text."""

    kind: ClaimKind
    subject: str | None  # object / part name as written ("can", "microwave door")
    value: object  # True/False, "open"/"closed", (target, positive) or a fraction 0..1
    text: str  # the clause it was read from, for verdict reasons

    def describe(self) -> str:
        return self.text.strip()


@dataclass
class Mention:
    """Something a clause names: kind grip | robot | obj | place, its text and span."""

    kind: str
    text: str
    start: int
    end: int


_PARTS = ("door", "drawer", "knob", "dial", "button", "handle")
_NEG = re.compile(
    r"\b(?:not|never|no\s+longer|yet\s+to|without|no|nor)\b|n't\b|\bhas\s+yet\s+to\b", re.I
)
_INTENT = re.compile(
    r"(?:\b(?:to|will|would|might|may|could|should|must|before|until|trying|preparing|"
    r"ready|about|going|attempting|planning|intends?|wants?|aims?|needs?)\s+(?:be\s+)?"
    r"(?:\w+ly\s+)?)$",
    re.I,
)
_YET_TO = re.compile(r"\byet\s+to\s+(?:\w+ly\s+)?$", re.I)

_GRIP_OPEN = re.compile(r"\b(?:open|opened|opens|apart|spread)\b", re.I)
_GRIP_CLOSED = re.compile(
    r"\b(?:closed|closes|close|shut|clamped|clenched|come\s+together)\b", re.I
)
_ADJ_GRIPPER = re.compile(r"\b(?P<s>open|opened|closed)\s+gripper\b", re.I)

_HOLD = re.compile(
    r"\b(?:hold|holds|holding|grasp|grasps|grasped|grasping|grip|grips|gripped|gripping|"
    r"grab|grabs|grabbed|grabbing|secured|secures|securing|clasp|clasps|clasped|clasping|"
    r"clutch\w*|carry|carries|carried|carrying|transport\w*|"
    r"has\s+(?:a\s+)?(?:firm\s+|secure\s+|tight\s+|good\s+)?(?:grip|grasp|hold)\s+(?:on|of)|"
    r"(?:wrapped|clamped)\s+around|moving|moves|moved|"
    r"lifting|lifts|lifted|raising|raises|raised|picking\s+up|picks\s+up|picked\s+up|"
    r"picked|has\s+picked)\s+(?=the\b|a\b|an\b|it\b|its\b|onto\b)",
    re.I,
)
_LIFT_VERB = re.compile(r"\b(?:lift|rais|pick)", re.I)
_HOLD_PASSIVE = re.compile(
    r"^\s*(?:(?:is|are|remains|stays|still|now|being|appears|seems|to|be|has|been|securely|"
    r"firmly|tightly|safely|not|no\s+longer|isn't|yet)\s+)*"
    r"(?:held|grasped|gripped|clamped|clutched|carried|grabbed|secured|clasped)\b"
    r"|^\s*(?:(?:is|are|remains|stays|still|now|securely|firmly|safely|not|no\s+longer|"
    r"isn't|yet)\s+)*"
    r"(?:in|between|within)\s+(?:the\s+|its\s+)?(?:robot's\s+)?(?:gripper|hand|grip|claw|"
    r"grasp|fingers|gripper\s+fingers)\b",
    re.I,
)
_RELEASE = re.compile(
    r"\b(?:released|releases|releasing|release|let\s+go|lets\s+go|letting\s+go|dropped|drops|"
    r"dropping|opened\s+(?:its\s+)?(?:gripper\s+)?to\s+release|"
    r"(?:slips|slipped|slipping|falls|fell|falling)\s+(?:out\s+of|from)|has\s+fallen\s+from)"
    r"\b(?:\s+of)?",
    re.I,
)
_EMPTY = re.compile(
    r"\b(?:gripper|hand|claw)\s+(?:(?:is|remains|appears|seems|looks)(?:\s+to\s+be)?\s+)?"
    r"(?:now\s+|still\s+)?(?P<e1>empty)\b|\b(?P<e2>empty)\s+(?:gripper|hand)\b"
    r"|\b(?:holding|holds|carrying|grasping|gripping|has)\s+(?P<e3>nothing)\b"
    r"|\b(?P<e4>nothing)\s+(?:is\s+)?(?:in|between)\s+(?:the|its)\s+(?:gripper|hand|grip|fingers)"
    r"|\b(?:holding|holds|carrying|grasping|gripping)\s+(?P<any>anything)\b"
    r"|\b(?P<e5>no)\s+(?:object|item|thing)\s+is\s+(?:currently\s+|now\s+)?(?:being\s+)?"
    r"(?:held|grasped|gripped|in\s+the\s+gripper)",
    re.I,
)
_CONTACT = re.compile(
    r"\b(?:touch|touches|touching|touched|contacts|contacting|contacted|in\s+contact\s+with|"
    r"(?:made|makes|making)\s+contact\s+with|contact\s+with|pressed\s+against|presses\s+against|"
    r"pressing\s+against|rest(?:s|ing)?\s+against|pressing\s+(?:down\s+)?on|"
    r"pushing\s+(?:down\s+)?on|interacted\s+with|interacting\s+with|"
    r"(?:closed|closes|closing|tightened)\s+(?:around|on))\b",
    re.I,
)
_CONTACT_PASSIVE = re.compile(
    r"^\s*(?:(?:is|are|has|have|been|being|not|yet|now|still|n't|never)\s+)*"
    r"(?:touched|contacted)\b",
    re.I,
)
_PUSH_DOWN = re.compile(
    r"\b(?:pushing|pressing|pushes|presses)\s+(?:the\s+)?(?:\w+\s+)?button\s+(?:down|in)\b", re.I
)
_CONTACT_ANY = re.compile(
    r"\b(?:touching|contacting|in\s+contact\s+with)\s+(?P<w>anything|nothing)\b", re.I
)
_LIFTED = re.compile(
    r"\b(?:lifted|raised|elevated|suspended|airborne|(?:in|through)\s+(?:the\s+)?(?:mid-?)?air|"
    r"off\s+the\s+(?:table|ground|surface|counter|floor|tabletop)|"
    r"above\s+the\s+(?:table|surface|ground|counter|tabletop)|picked\s+up|"
    r"left\s+the\s+(?:table|surface|ground))\b",
    re.I,
)
_ON_TABLE = re.compile(
    r"\b(?:on|upon|atop)\s+(?:the\s+|its\s+)?(?:table|tabletop|surface|counter|ground|floor|"
    r"work\s+surface)\b",
    re.I,
)
_AT_START = re.compile(
    r"\b(?:original|initial|starting|start)\s+(?:location|position|place|spot|orientation)\b"
    r"|\bwhere\s+it\s+(?:started|began|was)\b",
    re.I,
)
_IN_PLACE = re.compile(
    r"\b(?P<how>inside|into|in|within|out\s+of|outside(?:\s+of)?|reached|reaches|reach|"
    r"onto|on|over|around|encircles|encircling|surrounds|surrounding)\s+(?:the\s+|its\s+|a\s+)?(?=(?:\w+\s+){0,2}?(?:bin|peg|post|rod)\b)",
    re.I,
)
_ON_OBJ = re.compile(r"\b(?:stacked\s+)?(?:on\s+top\s+of|onto|on|atop|upon)\s+(?:the\s+)?", re.I)
_PRESSED = re.compile(
    r"\b(?:pressed|pushed|depressed)(?:\s+(?:down|in))?\b(?!\s+(?:against|on)\b)", re.I
)
_BUTTON_UP = re.compile(r"\bbutton\s+is\s+(?:still\s+)?(?:up|raised|unpressed)\b", re.I)
_PART_OPEN = re.compile(
    r"\b(?:open|opened|ajar|pulled\s+(?:\w+\s+){0,3}?out|pulled\s+open|swung\s+(?:wide\s+)?open)\b",
    re.I,
)
_PART_CLOSED = re.compile(r"\b(?:closed|shut|pushed\s+in|pushed\s+closed)\b", re.I)
_PART_TURNED = re.compile(r"\b(?:turned|rotated|twisted)\b", re.I)
_FULL = re.compile(r"\b(?:fully|completely|wide|all\s+the\s+way|entirely)\b", re.I)
_PARTLY = re.compile(
    r"\b(?:partially|partly|slightly|partway|part\s+of\s+the\s+way|a\s+bit|somewhat|a\s+little|"
    r"ajar)\b",
    re.I,
)
_HALF = re.compile(r"\b(?:half|halfway|half-way)\b", re.I)
_ALMOST = re.compile(r"\b(?:almost|nearly)\b", re.I)
_PCT = re.compile(r"(?P<n>\d+(?:\.\d+)?)\s*(?:%|percent)", re.I)


def _neg(text: str) -> bool:
    return bool(_NEG.search(text))


_HEDGE = re.compile(
    r"\b(?:appears?|seems?|looks?|is\s+likely|happens?)\s+to\s+(?:be\s+)?(?:\w+ly\s+)?$", re.I
)


def _intended(clause: str, at: int) -> bool:
    """Is the word at `at` something the robot is about to do, not something done?

    "about to grasp", "preparing to press" are intentions; "appears to be closed" is a
    hedged statement (still a claim) and "has yet to grasp" a negated one.
    """
    before = clause[max(0, at - 40) : at]
    if _YET_TO.search(before) or _HEDGE.search(before):
        return False
    return bool(_INTENT.search(before))


def _first(ms: list[Mention], kinds: tuple[str, ...], after: int = -1, before: int = 10**9):
    for m in ms:
        if m.kind in kinds and after <= m.start < before:
            return m
    return None


def _last(ms: list[Mention], kinds: tuple[str, ...], before: int):
    found = None
    for m in ms:
        if m.kind in kinds and m.end <= before:
            found = m
    return found


def _add(out: list[Claim], claim: Claim) -> None:
    if not any(c.kind == claim.kind and c.subject == claim.subject for c in out):
        out.append(claim)


def clause_claims(clause: str, ms: list[Mention]) -> list[Claim]:
    out: list[Claim] = []
    neg = _neg(clause)
    objs = [m for m in ms if m.kind == "obj"]
    parts = [m for m in objs if any(p in m.text.split() for p in _PARTS)]
    text = clause
    # holding: "nothing in the gripper", "not holding anything"
    for m in _EMPTY.finditer(clause):
        if _intended(clause, m.start()):
            continue
        rest_neg = _neg(clause[: m.start()] + " " + clause[m.end() :]) or "n't" in m.group(0)
        if m.group("any"):
            _add(out, Claim("holding_any", None, not neg, text))
        else:
            _add(out, Claim("holding_any", None, rest_neg, text))
    for m in _CONTACT_ANY.finditer(clause):
        nothing = m.group("w").lower() == "nothing"
        _add(out, Claim("contact_any", None, (not neg) if not nothing else False, text))
    # gripper open / closed: the state word belongs to the nearest mention before it
    for pat, state in ((_GRIP_OPEN, "open"), (_GRIP_CLOSED, "closed")):
        for m in pat.finditer(clause):
            owner = _last(ms, ("grip", "obj", "robot"), m.start())
            if owner is None or owner.kind != "grip" or _intended(clause, m.start()):
                continue
            if re.match(r"\s+to\s+release", clause[m.end() :]):
                continue
            value = state if not neg else ("closed" if state == "open" else "open")
            _add(out, Claim("gripper", "gripper", value, text))
    for m in _ADJ_GRIPPER.finditer(clause):
        state = "open" if m.group("s").lower().startswith("open") else "closed"
        _add(out, Claim("gripper", "gripper", state, text))
    # holding: active verbs with their object, passive "X is held", releases
    for m in _HOLD.finditer(clause):
        obj = _first(objs, ("obj",), after=m.end() - 1)
        if obj is None or _intended(clause, m.start()) or obj in parts and "button" in obj.text:
            continue
        verb = m.group(0).lower()
        if re.match(r"(?:lifted|raised|moved|picked)\b", verb) and not re.search(
            r"\b(?:has|have|had|robot|arm|gripper)\s+(?:\w+\s+)?$", clause[: m.start()]
        ):
            continue  # "the can is lifted": a state, read below
        _add(out, Claim("holding", obj.text, not neg, text))
        if _LIFT_VERB.search(verb) and obj.text.split()[-1] not in _PARTS:
            _add(out, Claim("lifted", obj.text, not neg, text))
    for obj in objs:
        tail = clause[obj.end :]
        if _HOLD_PASSIVE.match(tail):
            _add(out, Claim("holding", obj.text, not neg, text))
        if _CONTACT_PASSIVE.match(tail):
            _add(out, Claim("contact", obj.text, not neg, text))
    for m in _RELEASE.finditer(clause):
        if _intended(clause, m.start()):
            continue
        obj = _first(objs, ("obj",), after=m.end() - 1) or _last(ms, ("obj",), m.start())
        if obj is not None:
            _add(out, Claim("holding", obj.text, neg, text))
        else:
            _add(out, Claim("holding_any", None, neg, text))
    # contact
    for m in _CONTACT.finditer(clause):
        if _intended(clause, m.start()) or _CONTACT_ANY.match(clause, m.start()):
            continue
        obj = _first(objs, ("obj",), after=m.end() - 1)
        if obj is not None:
            _add(out, Claim("contact", obj.text, not neg, text))
    # where an object is: lifted, on the table, at its start, in a bin / on a peg, on another
    subject = objs[0] if objs else None
    for m in _LIFTED.finditer(clause):
        owner = _last(ms, ("obj",), m.start()) or subject
        if owner is None or owner in parts or _intended(clause, m.start()):
            continue
        _add(out, Claim("lifted", owner.text, not neg, text))
    for m in _ON_TABLE.finditer(clause):
        owner = _last(ms, ("obj",), m.start())
        if (
            owner is None
            or owner in parts
            or _last(ms, ("grip", "robot", "obj"), m.start()) is not owner
        ):
            continue
        _add(out, Claim("on", owner.text, ("table", not neg), text))
    for m in _AT_START.finditer(clause):
        owner = _last(ms, ("obj",), m.start()) or subject
        if owner is not None:
            _add(out, Claim("at_start", owner.text, not neg, text))
    for m in _IN_PLACE.finditer(clause):
        owner = _last(ms, ("obj",), m.start())
        target = _first(ms, ("place", "obj"), after=m.end() - 1)
        if owner is None or target is None or target is owner or _intended(clause, m.start()):
            continue
        if owner.text.split()[-1] in ("peg", "post", "rod") + tuple(_PARTS):
            continue
        how = m.group("how").lower()
        positive = not how.startswith("out")
        if how in ("reach", "reaches", "reached") and _neg(clause):
            positive = True  # "has not reached the bin": the negation below flips it
        _add(out, Claim("inside", owner.text, (target.text, positive != neg), text))
    for m in _ON_OBJ.finditer(clause):
        owner = _last(ms, ("obj",), m.start())
        base = _first(ms, ("obj",), after=m.end() - 1)
        if owner is None or base is None or base is owner or _intended(clause, m.start()):
            continue
        if base.text.split()[-1] in ("peg", "post", "rod", "handle") or owner in parts:
            continue
        if clause[m.end() : base.start].strip():
            continue  # "on" must take the object directly
        _add(out, Claim("on", owner.text, (base.text, not neg), text))
    # articulated parts and buttons
    for part in parts:
        _part_claims(out, clause, part, neg, ms)
    return out


def _part_claims(out: list[Claim], clause: str, part: Mention, neg: bool, ms) -> None:
    name = part.text
    if "button" in name:
        if _BUTTON_UP.search(clause):
            _add(out, Claim("pressed", name, neg, clause))
            return
        if _PUSH_DOWN.search(clause) and not _intended(clause, _PUSH_DOWN.search(clause).start()):
            _add(out, Claim("pressed", name, not neg, clause))
            return
        for m in _PRESSED.finditer(clause):
            if not _intended(clause, m.start()):
                _add(out, Claim("pressed", name, not neg, clause))
                return
        return
    if name.split()[-1] == "handle":
        return
    if _AT_START.search(clause):  # "the knob is still in its original orientation"
        _add(out, Claim("articulation", name, "open" if neg else "closed", clause))
        return
    pct = _PCT.search(clause)
    words = [
        (m, st)
        for pat, st in ((_PART_OPEN, "open"), (_PART_CLOSED, "closed"), (_PART_TURNED, "turned"))
        for m in pat.finditer(clause)
    ]
    words = [
        (m, st)
        for m, st in words
        if not _intended(clause, m.start())
        and (_last(ms, ("grip", "obj"), m.start()) or part).kind != "grip"
    ]
    if not words:
        return
    m, state = min(words, key=lambda w: w[0].start())
    if state == "turned":
        state = "open"
    if pct is not None:
        frac = min(max(float(pct.group("n")) / 100.0, 0.0), 1.0)
        _add(out, Claim("articulation_pct", name, frac if state == "open" else 1 - frac, clause))
        return
    if _HALF.search(clause):
        _add(out, Claim("articulation_pct", name, 0.5, clause))
        return
    if _ALMOST.search(clause):
        frac = 0.85 if state == "open" else 0.15
        _add(out, Claim("articulation_pct", name, frac, clause))
        return
    if state == "open" and _FULL.search(clause):
        state = "fully_open"
    elif state == "open" and _PARTLY.search(clause):
        state = "partly_open"
    elif state == "closed" and _PARTLY.search(clause):
        state = "partly_closed"
    if neg:
        state = {
            "open": "closed",
            "closed": "open",
            "fully_open": "not_fully_open",
        }.get(state, "")
    if state:
        _add(out, Claim("articulation", name, state, clause))
