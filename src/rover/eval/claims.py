"""Reading checkable claims out of a frame description (used by the rule judge and QA).

A description such as "The gripper is closed. The robot is holding the can, which is
lifted above the table." makes claims about a handful of things the simulator records
(`FrameFacts`): gripper open/closed, what the gripper touches, what the robot holds,
whether an object is lifted, where it is, how far a door/drawer/knob is open or turned,
whether a button is pressed. Each regular expression below recognises one family of
phrasings (the oracle's sentences and common paraphrases); anything else is ignored, so
prose about motion ("the arm moves toward the can") yields no claim and is inconclusive.
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
    "articulation",
    "articulation_pct",
    "pressed",
]


@dataclass(frozen=True)
class Claim:
    """One statement about the scene: `kind`, its subject, the asserted value, the text."""

    kind: ClaimKind
    subject: str | None  # object / part name as written ("can", "microwave door")
    value: object  # True/False, "open"/"closed", a target name or a fraction 0..1
    text: str  # the matched words, for verdict reasons

    def describe(self) -> str:
        return self.text.strip()


_NEG = r"(?P<neg>not\s+|no\s+longer\s+|n't\s+|never\s+)?"
_NP = r"(?P<np>(?:[\w\-']+\s+){0,3}?[\w\-']+)"
_ART = r"(?:the|a|an)\s+"
_STOP = (
    r"(?=\s*(?:[,.;:!?)]|$|\s(?:and|while|but|with|as|which|that|after|before|because|so|"
    r"now|then|still|near|above|over|from|to|towards|toward|at|in|into|on|by|of)\b))"
)
_TARGET = r"(?P<target>(?:[\w\-']+\s+){0,3}?[\w\-']+)" + _STOP
_OBJ = r"(?P<obj>(?:[\w\-']+\s+){0,3}?[\w\-']+)" + _STOP
_BE = r"(?:is|are|'s|remains|stays|appears\s+to\s+be|seems\s+to\s+be|has\s+been|sits|rests|lies)"
_AGENT = (
    r"(?:robot(?:'s)?(?:\s+(?:arm|gripper|hand))?|gripper|arm|it|hand|end[\s-]effector|and|but)"
)

_PATTERNS: list[tuple[ClaimKind, re.Pattern[str]]] = [
    (
        "gripper",
        re.compile(
            r"\bgripper(?:'s\s+fingers)?\s+(?:is|are|remains|stays|appears|has\s+been)\s+"
            r"(?:(?P<neg>not|no\s+longer)\s+)?(?:fully\s+|completely\s+|wide\s+|still\s+)?"
            r"(?P<state>open(?:ed)?|closed|close|shut)\b",
            re.I,
        ),
    ),
    ("gripper", re.compile(r"\b(?P<state>open|opened|closed)\s+gripper\b", re.I)),
    (
        "holding_any",
        re.compile(
            rf"\b{_AGENT}\s+(?:is\s+|isn't\s+|is\s+no\s+longer\s+)?{_NEG}"
            rf"(?:holding|grasping|gripping|carrying)\s+(?P<none>anything|nothing)\b",
            re.I,
        ),
    ),
    ("holding_any", re.compile(r"\bgripper\s+is\s+(?P<neg>not\s+)?(?P<none>empty)\b", re.I)),
    (
        "holding",
        re.compile(
            rf"\b{_AGENT}\s+(?:is\s+|has\s+|isn't\s+|is\s+still\s+|has\s+firmly\s+)?{_NEG}"
            rf"(?:holding|grasping|gripping|carrying|holds|grasped|gripped|picked\s+up|"
            rf"lifted|lifting|picking\s+up)\s+(?:onto\s+)?{_ART}{_OBJ}",
            re.I,
        ),
    ),
    (
        "holding",
        re.compile(
            rf"\b(?:the\s+)?{_NP}\s+(?:is|remains)\s+{_NEG}(?:held|grasped|gripped)\b"
            rf"|\bthe\s+{_NP.replace('np', 'np2')}\s+(?:is|remains)\s+{_NEG.replace('neg', 'neg2')}"
            rf"in\s+the\s+(?:robot's\s+)?(?:gripper|hand)\b",
            re.I,
        ),
    ),
    (
        "contact_any",
        re.compile(
            rf"\b{_AGENT}\s+(?:is\s+|isn't\s+)?{_NEG}(?:touching|contacting|in\s+contact\s+with)"
            rf"\s+(?P<none>anything|nothing)\b",
            re.I,
        ),
    ),
    (
        "contact",
        re.compile(
            rf"\b{_AGENT}(?:'s\s+fingers)?\s+(?:is\s+|are\s+|has\s+|isn't\s+)?{_NEG}"
            rf"(?:touching|contacting|in\s+contact\s+with|made\s+contact\s+with|touched|"
            rf"making\s+contact\s+with)\s+{_ART}{_OBJ}",
            re.I,
        ),
    ),
    (
        "articulation_pct",
        re.compile(
            rf"\bthe\s+{_NP}\s+(?:is|has\s+been)\s+(?:about\s+|approximately\s+|roughly\s+|"
            rf"around\s+|now\s+)?(?P<pct>\d+(?:\.\d+)?)\s*(?:%|percent)\s*"
            rf"(?P<state>open(?:ed)?|closed|turned|rotated)\b",
            re.I,
        ),
    ),
    (
        "lifted",
        re.compile(
            rf"\bthe\s+{_NP}\s+{_BE}\s+{_NEG}(?:now\s+|still\s+)?"
            rf"(?P<how>lifted|raised|in\s+the\s+air|off\s+the\s+(?:table|counter|ground|floor)|"
            rf"picked\s+up|being\s+lifted)\b",
            re.I,
        ),
    ),
    (
        "inside",
        re.compile(
            rf"\bthe\s+{_NP}\s+{_BE}\s+{_NEG}(?:now\s+|still\s+)?(?:inside|in|within)\s+"
            rf"(?:the\s+)?(?!air\b|robot|gripper|hand)(?:(?:robot's|its)\s+)?{_TARGET}",
            re.I,
        ),
    ),
    (
        "on",
        re.compile(
            rf"\bthe\s+{_NP}\s+{_BE}\s+{_NEG}(?:now\s+|still\s+)?(?:on\s+top\s+of|on|upon|"
            rf"resting\s+on|sitting\s+on|lying\s+on)\s+(?:the\s+)?{_TARGET}",
            re.I,
        ),
    ),
    (
        "pressed",
        re.compile(
            rf"\bthe\s+{_NP}\s+(?:is|was|has\s+(?:not\s+|never\s+)?been)\s+{_NEG}(?:now\s+)?"
            rf"(?:pressed|pushed|depressed)\b"
            rf"|\b(?:robot|gripper|it)\s+(?:has\s+)?{_NEG.replace('neg', 'neg2')}"
            rf"(?:pressed|pushed|presses|pushes)\s+the\s+{_OBJ.replace('obj', 'np2')}",
            re.I,
        ),
    ),
    (
        "articulation",
        re.compile(
            rf"\bthe\s+{_NP}\s+(?:is|remains|stays|has\s+been)\s+{_NEG}"
            rf"(?P<deg>fully\s+|completely\s+|partially\s+|half\s+|slightly\s+|wide\s+)?"
            rf"(?P<state>open(?:ed)?|closed|shut)\b",
            re.I,
        ),
    ),
]

_NOT_BEEN = re.compile(r"\b(?:not|never)\s+been\b")
_SENTENCE = re.compile(r"(?<=[.!?;])\s+|\n+")


def _neg(m: re.Match[str]) -> bool:
    g = m.groupdict()
    text = m.group(0).lower()
    return bool(g.get("neg") or g.get("neg2")) or "n't" in text or bool(_NOT_BEEN.search(text))


def _np(m: re.Match[str]) -> str | None:
    g = m.groupdict()
    return g.get("np") or g.get("np2")


def extract_claims(description: str | None) -> list[Claim]:
    """Every checkable claim in a description, in reading order."""
    if not description:
        return []
    claims: list[Claim] = []
    for sentence in _SENTENCE.split(description):
        claims.extend(_sentence_claims(sentence.strip()))
    return claims


def _sentence_claims(s: str) -> list[Claim]:
    found: list[tuple[int, Claim]] = []
    taken: list[tuple[int, int]] = []
    for kind, pat in _PATTERNS:
        for m in pat.finditer(s):
            span = m.span()
            if any(a < span[1] and span[0] < b for a, b in taken):
                continue  # an earlier (more specific) pattern already read these words
            claim = _to_claim(kind, m)
            if claim is not None:
                taken.append(span)
                found.append((span[0], claim))
    return [c for _, c in sorted(found, key=lambda x: x[0])]


def _to_claim(kind: ClaimKind, m: re.Match[str]) -> Claim | None:
    neg = _neg(m)
    text = m.group(0)
    g = m.groupdict()
    if kind == "gripper":
        state = "open" if g["state"].lower().startswith("open") else "closed"
        if neg:
            state = "closed" if state == "open" else "open"
        return Claim("gripper", "gripper", state, text)
    if kind in ("holding_any", "contact_any"):
        none_word = g["none"].lower()
        # "holding nothing" / "gripper is empty" assert emptiness; "not holding anything" too
        empty = (none_word in ("nothing", "empty")) != neg if none_word != "anything" else neg
        return Claim(kind, None, not empty, text)
    if kind in ("holding", "contact"):
        subject = g.get("obj") or _np(m)
        if not subject or _is_pronoun(subject):
            return None
        return Claim(kind, _clean(subject), not neg, text)
    subject = _np(m)
    if not subject or _is_pronoun(subject) or "gripper" in subject.lower():
        return None
    subject = _clean(subject)
    if kind == "articulation_pct":
        frac = float(g["pct"]) / 100.0
        if g["state"].lower().startswith("clos"):
            frac = 1.0 - frac
        return Claim("articulation_pct", subject, min(max(frac, 0.0), 1.0), text)
    if kind == "articulation":
        state = "open" if g["state"].lower().startswith("open") else "closed"
        deg = (g.get("deg") or "").strip().lower()
        if deg in ("partially", "half", "slightly"):
            state = "partly_open" if state == "open" else "partly_closed"
        if neg:
            state = {"open": "closed", "closed": "open"}.get(state, "unknown")
        return None if state == "unknown" else Claim("articulation", subject, state, text)
    if kind == "lifted":
        how = g["how"].lower()
        return Claim("lifted", subject, not neg, text) if how else None
    if kind in ("inside", "on"):
        target = _clean(g["target"])
        if kind == "on" and target in ("top",):
            return None
        return Claim(kind, subject, (target, not neg), text)
    if kind == "pressed":
        return Claim("pressed", subject, not neg, text)
    return None


_PRONOUNS = {"it", "this", "that", "them", "something", "object", "item"}
_ARTICLES = re.compile(r"^(?:the|a|an|its|robot's|their)\s+", re.I)


def _is_pronoun(np: str) -> bool:
    return np.strip().lower() in _PRONOUNS


def _clean(name: str) -> str:
    name = name.strip().lower().replace("_", " ")
    while True:
        new = _ARTICLES.sub("", name)
        if new == name:
            return name
        name = new


def normalise_name(name: str) -> str:
    """Lower case, spaces for underscores, no leading article."""
    return _clean(name)


def names_match(said: str, known: str) -> bool:
    """Does a name from the text refer to a name the simulator uses?

    "can", "soda can", "the can" all match "can"; "bin 2" matches "bin_2" and "bin2" but
    not "bin 1" (a trailing number must agree); "microwave door" matches "door".
    """
    a, b = normalise_name(said), normalise_name(known)
    if a == b or a.replace(" ", "") == b.replace(" ", ""):
        return True
    ta, tb = a.split(), b.split()
    if not ta or not tb:
        return False
    if ta[-1].isdigit() or tb[-1].isdigit():
        return ta[-2:] == tb[-2:] if len(ta) > 1 and len(tb) > 1 else False
    return ta[-1] == tb[-1] or a.endswith(" " + b) or b.endswith(" " + a)
