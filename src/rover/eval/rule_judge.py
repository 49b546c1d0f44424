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

from dataclasses import dataclass, field
from typing import Literal

from rover.episode import FrameFacts
from rover.eval.claims import Claim, extract_claims, names_match

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
        ok = check_claim(claim, facts)
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
    return names


def _resolve(name: str | None, candidates: list[str]) -> str | None:
    if not name:
        return None
    for c in candidates:
        if names_match(name, c):
            return c
    return None


def check_claim(claim: Claim, facts: FrameFacts) -> bool | None:
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
        held = facts.holding is not None and names_match(claim.subject or "", facts.holding)
        if claim.value:
            if held:
                return True
            # holding something else (or nothing): false if we know the object at all
            return False if facts.holding is None or _resolve(claim.subject, known) else None
        return not held
    if k == "contact":
        if _resolve(claim.subject, list(facts.contacts)) is not None:
            return bool(claim.value)
        # not touching it: decided when we know the object, or the gripper touches nothing
        if _resolve(claim.subject, known) is not None or not facts.contacts:
            return not claim.value
        return None
    if k in ("lifted", "inside", "on"):
        return _check_object(claim, facts)
    if k in ("articulation", "articulation_pct"):
        return _check_articulation(claim, facts)
    if k == "pressed":
        return _check_pressed(claim, facts)
    return None


def _check_object(claim: Claim, facts: FrameFacts) -> bool | None:
    name = _resolve(claim.subject, list(facts.objects))
    if name is None:
        return None
    obj = facts.objects[name]
    if claim.kind == "lifted":
        return obj.lifted == claim.value
    target, positive = claim.value  # type: ignore[misc]
    where = obj.inside if claim.kind == "inside" else obj.on
    if claim.kind == "on" and where is None:
        # resting on something contradicts being lifted; otherwise the facts are silent
        return (not positive) if obj.lifted and positive else None
    if where is None:
        return not positive
    return names_match(target, where) == positive


def _articulation_value(claim: Claim, facts: FrameFacts) -> float | None:
    name = _resolve(claim.subject, list(facts.articulations))
    return None if name is None else float(facts.articulations[name])


def _check_articulation(claim: Claim, facts: FrameFacts) -> bool | None:
    value = _articulation_value(claim, facts)
    if value is None:
        return None
    if claim.kind == "articulation_pct":
        return abs(value - float(claim.value)) <= PCT_TOLERANCE  # type: ignore[arg-type]
    state = claim.value
    if state == "open":
        fully = "fully" in claim.text.lower() or "completely" in claim.text.lower()
        return value >= FULLY_OPEN_MIN if fully else value > OPEN_MIN
    if state == "closed":
        return value <= CLOSED_MAX
    if state == "partly_open":
        return OPEN_MIN < value < FULLY_OPEN_MIN
    if state == "partly_closed":
        return CLOSED_MAX < value < FULLY_OPEN_MIN
    return None


def _check_pressed(claim: Claim, facts: FrameFacts) -> bool | None:
    if _resolve(claim.subject, list(facts.pressed)) is not None:
        return bool(claim.value)
    value = _articulation_value(claim, facts)
    if value is not None:
        return (value >= PRESSED_MIN) == claim.value
    if claim.subject and "button" in claim.subject:
        return not claim.value  # a button the facts do not list as pressed is not pressed
    return None
