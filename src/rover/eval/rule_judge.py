"""The offline Task 2 judge: check each claim of a description against simulator facts.

App. C.2 judges a frame description as containing something verifiably false (an error)
or something verifiably true and nothing false (a success); everything else is
inconclusive. The paper asks an LLM; this judge does the same job deterministically for
the claim families `rover.eval.claims` recognises, which covers the oracle's vocabulary
and common paraphrases. It needs no network and is exact on those claims, which makes it
the reference for testing: inject k false claims, measure k.

Tolerances: an articulation percentage is true within ±`PCT_TOLERANCE` of the simulator's
fraction; "open" means more than `OPEN_MIN`, "closed" at most `CLOSED_MAX`, "fully open"
at least `FULLY_OPEN_MIN`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Literal

from rover.episode import FrameFacts
from rover.eval.claim_names import head_and_modifiers, names_match, normalise_name, resolve
from rover.eval.claims import Claim, extract_claims

PCT_TOLERANCE = 0.15
OPEN_MIN = 0.1
CLOSED_MAX = 0.1
FULLY_OPEN_MIN = 0.9
PRESSED_MIN = 0.5

Verdict = Literal["true", "false", "inconclusive"]


@dataclass
class FrameJudgement:
    """The verdict on one frame description, with the claims that decided it."""

    verdict: Verdict
    true_claims: list[str] = field(default_factory=list)
    false_claims: list[str] = field(default_factory=list)
    reason: str = ""


def frame_verdict(n_true: int, n_false: int) -> Verdict:
    """App. C.2: any false statement -> false; else any true statement -> true."""
    if n_false:
        return "false"
    return "true" if n_true else "inconclusive"


def judge_description(
    description: str | None, facts: FrameFacts | None, task: str | None = None
) -> FrameJudgement:
    """Judge one description against one frame's facts (`task` names "the target bin")."""
    if facts is None:
        return FrameJudgement("inconclusive", reason="no simulator facts for this frame")
    if not description:
        return FrameJudgement("inconclusive", reason="no description")
    true_c: list[str] = []
    false_c: list[str] = []
    for claim in extract_claims(description):
        ok = check_claim(claim, facts, task)
        if ok is True:
            true_c.append(claim.describe())
        elif ok is False:
            false_c.append(claim.describe())
    verdict = frame_verdict(len(true_c), len(false_c))
    reason = (
        f"contradicts facts: {'; '.join(false_c)}"
        if false_c
        else (f"matches facts: {'; '.join(true_c)}" if true_c else "no checkable claim")
    )
    return FrameJudgement(verdict, true_c, false_c, reason)


def known_names(facts: FrameFacts) -> list[str]:
    """Every object/part name the facts mention."""
    names = list(facts.objects) + list(facts.contacts) + list(facts.articulations)
    names += list(facts.pressed)
    if facts.holding:
        names.append(facts.holding)
    return list(dict.fromkeys(names))


def goal_of(task: str | None, obj: str) -> str | None:
    """The bin the task wants `obj` in: "... put the milk in bin 1 and the can in bin 4".

    The object is looked for by its name, then by its head noun ("cylindrical can" ->
    "can", "milk carton" -> "milk"); a task naming one bin gives that bin for anything.
    """
    if not task:
        return None
    head, _ = head_and_modifiers(obj)
    for name in dict.fromkeys([normalise_name(obj), head]):
        if not name:
            continue
        words = r"\s+".join(re.escape(w) for w in name.split())
        near = rf"\b{words}\s+(?:\w+\s+){{0,3}}?(?:in|into)\s+(bin\s*\d+)"
        m = re.search(near, task, re.I)
        if m:
            return m.group(1).lower()
    bins = set(re.findall(r"\b(?:in|into)\s+(bin\s*\d+)", task, re.I))
    return bins.pop().lower() if len(bins) == 1 else None


_GOAL_WORDS = re.compile(r"\b(?:target|goal|correct|destination|other|second)\b")
_START_WORDS = re.compile(r"\b(?:start|starting|original|initial|first)\b")


def _target(said: str, obj: str, task: str | None) -> str | None:
    """The facts' name for where the text says an object is ("the target bin" -> "bin 4")."""
    said = normalise_name(said)
    if re.search(r"\d", said) or said.split()[-1] in ("peg", "post", "rod"):
        return "peg" if said.split()[-1] in ("post", "rod") else said
    if _START_WORDS.search(said):
        return "start bin"
    if _GOAL_WORDS.search(said) or said in ("bin", "bins"):
        return goal_of(task, obj)
    return None


def check_claim(claim: Claim, facts: FrameFacts, task: str | None = None) -> bool | None:
    """True / False when the facts decide the claim, None when they cannot."""
    k = claim.kind
    if k == "gripper":
        return facts.gripper == claim.value
    if k == "holding_any":
        return (facts.holding is not None) == claim.value
    if k == "contact_any":
        return bool(facts.contacts) == claim.value
    known = known_names(facts)
    if k == "holding":
        name = resolve(claim.subject, known)
        held = facts.holding is not None and name == facts.holding
        if claim.value:
            if held:
                return True
            # holding something else (or nothing): false if we know the object at all
            return False if facts.holding is None or name is not None else None
        return None if name is None and facts.holding is not None else not held
    if k == "contact":
        name = resolve(claim.subject, known)
        if name is not None and name in facts.contacts:
            return bool(claim.value)
        # not touching it: decided when we know the object, or the gripper touches nothing
        if name is not None or not facts.contacts:
            return not claim.value
        return None
    if k in ("lifted", "inside", "on", "at_start"):
        return _check_object(claim, facts, task)
    if k in ("articulation", "articulation_pct"):
        return _check_articulation(claim, facts)
    if k == "pressed":
        return _check_pressed(claim, facts)
    return None


def _check_object(claim: Claim, facts: FrameFacts, task: str | None) -> bool | None:
    name = resolve(claim.subject, list(facts.objects))
    if name is None:
        return None
    obj = facts.objects[name]
    if claim.kind == "lifted":
        return obj.lifted == claim.value
    if claim.kind == "at_start":
        at_start = not obj.lifted and obj.inside in (None, "start bin") and facts.holding != name
        return at_start == claim.value
    said, positive = claim.value  # type: ignore[misc]
    if claim.kind == "on" and normalise_name(said) in ("table", "tabletop", "surface", "counter"):
        # resting on the table = not lifted and in no bin; in a bin the facts are silent
        if obj.lifted or (obj.on is not None and obj.on != "table"):
            return not positive
        return positive if obj.inside is None else None
    if claim.kind == "on":
        base = resolve(said, list(facts.objects))
        if base is None:
            return None
        return (obj.on == base) == positive
    target = _target(said, name, task)
    where = [w for w in (obj.inside, obj.on) if w]
    if target is None:
        # "in the bin" with no goal known: only "not in any bin yet" is decided
        return (not positive) if not where else None
    return any(names_match(target, w) for w in where) == positive


def _articulation_value(claim: Claim, facts: FrameFacts) -> float | None:
    name = resolve(claim.subject, list(facts.articulations))
    return None if name is None else float(facts.articulations[name])


def _check_articulation(claim: Claim, facts: FrameFacts) -> bool | None:
    value = _articulation_value(claim, facts)
    if value is None:
        return None
    if claim.kind == "articulation_pct":
        return abs(value - float(claim.value)) <= PCT_TOLERANCE  # type: ignore[arg-type]
    return {
        "open": value > OPEN_MIN,
        "closed": value <= CLOSED_MAX,
        "fully_open": value >= FULLY_OPEN_MIN,
        "not_fully_open": value < FULLY_OPEN_MIN,
        "partly_open": OPEN_MIN < value < FULLY_OPEN_MIN,
        "partly_closed": CLOSED_MAX < value < FULLY_OPEN_MIN,
    }.get(str(claim.value))


def _check_pressed(claim: Claim, facts: FrameFacts) -> bool | None:
    if resolve(claim.subject, list(facts.pressed)) is not None:
        return bool(claim.value)
    value = _articulation_value(claim, facts)
    if value is not None:
        return (value >= PRESSED_MIN) == claim.value
    if claim.subject and "button" in claim.subject:
        return not claim.value  # a button the facts do not list as pressed is not pressed
    return None
