"""How the QA half of the agreement corpus was written (called by `build.main`).

Every third frame of an episode (and every frame an event happens at) is described in one
model style with mostly true statements and, a quarter of the time, an invented one; the
episode's questions are then labelled by what those descriptions assert
(`described_event`), not by what happened: the answerer reads descriptions, so that is
what it must get right. Hand-written sequences (`handwritten.QA_SEQUENCES`) are added as
always-held-out cases.
"""

from __future__ import annotations

import random

from rover.episode import FrameFacts
from rover.eval.agreement import banks
from rover.eval.agreement.build import STYLES, candidates, pick, render
from rover.eval.agreement.handwritten import QA_SEQUENCES

_PART_RANGE = {
    "closed": (0.0, 0.1),
    "open": (0.1001, 1.0),
    "partly": (0.1001, 0.8999),
    "full": (0.9, 1.0),
}


def _claimed_range(atom: tuple) -> tuple[float, float]:
    if atom[2] == "pct":
        return atom[3], atom[3]
    return _PART_RANGE[atom[2]]


def described_event(item, frames_atoms: list[list[tuple]], target: str | None) -> int | None:
    """The first description index asserting the question's event (None: never asserted).

    The reading a person would make of the descriptions alone: contact = touching or
    holding it; grasp = holding it (or closed gripper touching it); pick up = it is lifted;
    place = it is in / on the target; drop = an explicit drop, or held before and released
    now without being in / on the target; start opening = claimed opening above 10%;
    completely open = at least 90%; start closing = below 90%; completely closed = at most
    10%; press / turn on = the button said to be pressed.
    """
    ev, obj = item.event, item.object
    was_held = False
    for i, atoms in enumerate(frames_atoms):
        held = any(a[0] == "holding" and a[1] == obj and a[2] for a in atoms)
        released = any(
            (a[0] == "holding" and a[1] == obj and not a[2]) or (a[0] == "holding_any" and not a[1])
            for a in atoms
        )
        touched = any(a[0] == "contact" and a[1] == obj and a[2] for a in atoms)
        closed = any(a[0] == "gripper" and a[1] == "closed" for a in atoms)
        lifted = any(a[0] == "lifted" and a[1] == obj and a[2] for a in atoms)
        placed = any(
            a[0] in ("inside", "on") and a[1] == obj and a[3] and (target is None or a[2] == target)
            for a in atoms
        )
        dropped = any(a[0] == "drop" and a[1] == obj for a in atoms)
        ranges = [_claimed_range(a) for a in atoms if a[0] == "part" and a[1] == obj]
        pressed = [a[1] for a in atoms if a[0] == "pressed"]
        hit = {
            "contact": touched or held,
            "grasp": held or (closed and touched),
            "pick_up": lifted,
            "place": placed,
            "drop": dropped or (was_held and released and not placed),
            "press": True in pressed,
            "turn_on": True in pressed,
            "open_start": any(lo > 0.1 for lo, _ in ranges),
            "turn_start": any(lo > 0.1 for lo, _ in ranges),
            "open_finish": any(lo >= 0.9 for lo, _ in ranges),
            "turn_finish": any(lo >= 0.9 for lo, _ in ranges),
            "close_start": any(hi < 0.9 for _, hi in ranges),
            "close_finish": any(hi <= 0.1 for _, hi in ranges),
        }.get(ev, False)
        if hit:
            return i
        if held:
            was_held = True
        elif released:
            was_held = False
    return None


DROP_TEXT = [
    "the {o} slips out of the gripper and falls",
    "the robot drops the {o}",
    "the {o} has fallen from the gripper",
]


def qa_descriptions(ep, style: str, rng: random.Random, hallucinate: float):
    """Descriptions of every third frame (and every event frame): text and atoms each."""
    n = len(ep.truth.facts)
    event_frames = {e.frame for e in ep.truth.events if e.frame is not None}
    positions = sorted(set(range(0, n, 3)) | event_frames)
    drops = {e.frame: e.object for e in ep.truth.events if e.name == "drop" and e.frame}
    texts, atoms_per = [], []
    for pos in positions:
        facts = ep.truth.facts[pos]
        cands = candidates(facts, ep.task, rng)
        wants = [True, True] if rng.random() < 0.7 else [True, None]
        if rng.random() < hallucinate:
            wants.append(False)
        stmts: list[tuple] = []
        for w in wants:
            s = pick(cands, w, facts, rng, used=[t[4] for t in stmts])
            if s is not None and all(s[0] != t[0] for t in stmts):
                stmts.append(s)
        if pos in drops and rng.random() < 0.7:
            o = drops[pos]
            t = rng.choice(DROP_TEXT).format(o=rng.choice(banks.ALIASES.get(o, [o])))
            stmts.append((t, [("drop", o)], o, None, "drop"))
        if not stmts:
            stmts.append((*rng.choice(cands["neutral"]), None, "neutral"))
        texts.append(render(stmts, style, rng))
        atoms_per.append([a for s in stmts for a in s[1]])
    return positions, texts, atoms_per


def build_qa(episodes, rng: random.Random) -> list[dict]:
    from rover.eval.qa_events import place_target

    cases = []
    for ep in episodes:
        qa = ep.truth.qa
        if not qa:
            continue
        for style in rng.sample(STYLES, 2):
            positions, texts, atoms = qa_descriptions(ep, style, rng, hallucinate=0.25)
            for item in qa:
                target = None
                place = [q for q in qa if q.event == "place" and q.object == item.object]
                if item.event in ("place", "drop") and place:
                    said = place_target(place[0]) or ""
                    target = _target_name(said, ep.truth.facts)
                at = described_event(item, atoms, target)
                label = item.model_copy(update={"answer": at is not None, "frame": at})
                cases.append(
                    {
                        "style": style,
                        "episode": ep.id,
                        "task": ep.task,
                        "family": ep.task_group,
                        "positions": positions,
                        "descriptions": texts,
                        "item": label.model_dump(mode="json"),
                        "qa": [q.model_dump(mode="json") for q in qa],
                    }
                )
    return cases


def _target_name(said: str, facts: list[FrameFacts]) -> str | None:
    """The facts' name for a question's target ("round peg" -> "peg", "bin 4")."""
    said = said.lower().strip()
    names = {o.inside for f in facts for o in f.objects.values() if o.inside}
    names |= {o.on for f in facts for o in f.objects.values() if o.on}
    for n in names:
        if n == said or said.endswith(" " + n) or n.endswith(" " + said):
            return n
    return said or None


def hand_qa_cases(episodes) -> list[dict]:
    """The hand-written QA sequences as cases, one per question; always held out."""
    by_id = {ep.id: ep for ep in episodes}
    out = []
    for seq in QA_SEQUENCES:
        ep = by_id[seq["episode"]]
        n, k = ep.num_frames, len(seq["descriptions"])
        positions = [round(i * (n - 1) / max(k - 1, 1)) for i in range(k)]
        answers = dict(seq["answers"])
        for item in ep.truth.qa:
            key = (
                f"{item.event}:{item.object}"
                if f"{item.event}:{item.object}" in answers
                else item.event
            )
            at = answers.pop(key)
            label = item.model_copy(update={"answer": at is not None, "frame": at})
            out.append(
                {
                    "style": "handwritten-fresh",
                    "force": "heldout",
                    "episode": ep.id,
                    "task": ep.task,
                    "family": ep.task_group,
                    "positions": positions,
                    "descriptions": list(seq["descriptions"]),
                    "item": label.model_dump(mode="json"),
                    "qa": [q.model_dump(mode="json") for q in ep.truth.qa],
                }
            )
        if answers:
            raise ValueError(f"{ep.id}: answers for questions it does not ask: {answers}")
    return out
