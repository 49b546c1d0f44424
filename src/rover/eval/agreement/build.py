"""How the agreement corpus was written (run once; the JSON it writes is what is used).

    python -m rover.eval.agreement.build DATASET_DIR [DATASET_DIR ...]

For chosen frames of every episode, descriptions are composed from the phrase banks in
`banks.py` in three model styles (GPT-4o: full prose with hedges and pronouns; Gemini 2.5:
markdown labels and bullets; Qwen2.5-VL: short comma-joined clauses) with object aliases.
Every statement carries the atoms it asserts; `atom_truth` decides each atom from the
frame's facts the way a person reading the facts would (a hedge still asserts; "on the
table" means not lifted for an object standing on the table; a percentage within 15
points is right, beyond 25 wrong, in between never generated). The label is App. C.2's
rule over the statements. QA cases describe a sequence of frames the same way (mostly
true statements, some invented ones) and label each question by what the descriptions
assert, with `described_event`. The hand-written cases (`handwritten.py`) are added as
they are. Cases are split into dev / held-out halves by a seeded shuffle.
"""

from __future__ import annotations

import json
import random
import re
import sys
from pathlib import Path

from rover.episode import FrameFacts
from rover.eval.agreement import CORPUS_VERSION, banks
from rover.eval.agreement.handwritten import FRAME_CASES as HAND_FRAMES
from rover.eval.agreement.handwritten import FRESH_CASES, SET_A_CASES
from rover.eval.rule_judge import frame_verdict

STYLES = ("gpt-4o", "gemini-2.5", "qwen2.5-vl")
PARTS = ("door", "drawer", "knob")
FIXED = {"door", "drawer", "knob", "button", "peg"}  # never lifted or held as objects


def goal_target(task: str, obj: str = "") -> str | None:
    """The bin the task wants `obj` in ("... the can in bin 4" -> "bin 4")."""
    m = None
    if obj:
        near = rf"\b{re.escape(obj)}\s+(?:\w+\s+){{0,3}}?(?:in|into)\s+(bin\s*\d+)"
        m = re.search(near, task, re.I)
    m = m or re.search(r"\b(?:in|into)\s+(bin\s*\d+)", task, re.I)
    return m.group(1).lower() if m else None


def atom_truth(atom: tuple, facts: FrameFacts) -> bool | None:
    """Is one asserted atom true of the facts (None: not decidable, never generated)."""
    kind = atom[0]
    if kind == "gripper":
        return facts.gripper == atom[1]
    if kind == "holding":
        return (facts.holding == atom[1]) == atom[2]
    if kind == "holding_any":
        return (facts.holding is not None) == atom[1]
    if kind == "contact":
        return (atom[1] in facts.contacts) == atom[2]
    if kind == "contact_any":
        return bool(facts.contacts) == atom[1]
    obj = facts.objects.get(atom[1]) if kind in ("lifted", "inside", "on") else None
    if kind == "lifted":
        return None if obj is None else obj.lifted == atom[2]
    if kind == "inside":
        return None if obj is None else (obj.inside == atom[2]) == atom[3]
    if kind == "on":
        return None if obj is None else (obj.on == atom[2]) == atom[3]
    if kind == "part":
        v = facts.articulations.get(atom[1])
        if v is None:
            return None
        state = atom[2]
        if state == "pct":
            d = abs(v - atom[3])
            return True if d <= 0.15 else (False if d > 0.25 else None)
        return {
            "closed": v <= 0.1,
            "open": v > 0.1,
            "partly": 0.1 < v < 0.9,
            "full": v >= 0.9,
        }[state]
    if kind == "pressed":
        return ("button" in facts.pressed) == atom[1]
    return None


def _fill(template: str, atoms: list[tuple], **names: str) -> tuple[str, list[tuple]]:
    def sub(x):
        if isinstance(x, str) and x.startswith("{") and x.endswith("}"):
            return names[x[1:-1] + "_name"]
        return x

    text = template.format(**{k: v for k, v in names.items() if not k.endswith("_name")})
    return text, [tuple(sub(x) for x in a) for a in atoms]


def candidates(facts: FrameFacts, task: str, rng: random.Random) -> dict[str, list[tuple]]:
    """Every statement this frame could carry, by kind: (text, atoms, subject name)."""
    out: dict[str, list[tuple]] = {}
    objs = [o for o in facts.objects if o not in FIXED]
    alias = {o: rng.choice(banks.ALIASES.get(o, [o])) for o in facts.objects}
    # a door or drawer is grasped and touched by its handle
    grip = {
        o: rng.choice([f"{o} handle", "handle", o]) if o in ("door", "drawer") else a
        for o, a in alias.items()
    }
    for state, texts in banks.GRIPPER.items():
        out.setdefault("gripper", []).extend((t, [("gripper", state)], None) for t in texts)
    holdable = objs + [o for o in facts.objects if o in ("door", "drawer", "knob")]
    for o in holdable:
        for t, atoms in banks.HOLD_POS + banks.HOLD_NEG:
            out.setdefault("hold", []).append((*_fill(t, atoms, o=grip[o], o_name=o), o))
    for o in list(facts.objects):
        for t, atoms in banks.CONTACT_POS + banks.CONTACT_NEG:
            out.setdefault("contact", []).append((*_fill(t, atoms, o=grip[o], o_name=o), o))
    for o in objs:
        of = facts.objects[o]
        goal = goal_target(task, o)
        lift = banks.LIFT_POS + banks.LIFT_NEG
        if of.inside is None and of.on in (None, "table"):
            lift = lift + banks.TABLE_POS
        for t, atoms in lift:
            out.setdefault("lifted", []).append((*_fill(t, atoms, o=alias[o], o_name=o), o))
        for t, atoms in banks.LIFT_ACTION:
            out.setdefault("lift_action", []).append((*_fill(t, atoms, o=alias[o], o_name=o), o))
        places = []
        if goal:
            places += [(goal, goal), (goal, "the target bin"), (goal, "the goal bin")]
        if of.inside == "start bin" or goal:
            places += [("start bin", "the start bin"), ("start bin", "the starting bin")]
        if "peg" in facts.objects:
            places += [("peg", "the peg")]
        for name, said in places:
            for t, atoms in banks.INSIDE_POS + banks.INSIDE_NEG:
                out.setdefault("inside", []).append(
                    (*_fill(t, atoms, o=alias[o], o_name=o, t=said, t_name=name), o)
                )
            if name != "start bin":
                for t, atoms in banks.PLACE_RELEASE:
                    out.setdefault("place_release", []).append(
                        (*_fill(t, atoms, o=alias[o], o_name=o, t=said, t_name=name), o)
                    )
        for b in objs:
            if b != o:
                for t, atoms in banks.ON_POS + banks.ON_NEG:
                    out.setdefault("on", []).append(
                        (*_fill(t, atoms, o=alias[o], o_name=o, b=alias[b], b_name=b), o)
                    )
    for p, v in facts.articulations.items():
        if p not in PARTS:
            continue
        table = banks.PART_TURN if p == "knob" else banks.PART_OPEN
        for state, texts in table.items():
            for t in texts:
                if state == "pct":
                    near = round(v * 100 / 5) * 5
                    for pct in {near if near >= 10 else 15, rng.choice(range(10, 95, 5))}:
                        text = t.format(p=alias[p], pct=pct)
                        out.setdefault("part", []).append(
                            (text, [("part", p, "pct", pct / 100)], p)
                        )
                else:
                    out.setdefault("part", []).append(
                        (t.format(p=alias[p]), [("part", p, state)], p)
                    )
    if "button" in facts.objects or "button" in facts.articulations:
        for t in banks.PRESS_POS:
            out.setdefault("pressed", []).append((t, [("pressed", True)], "button"))
        for t in banks.PRESS_NEG:
            out.setdefault("pressed", []).append((t, [("pressed", False)], "button"))
    main = (objs or list(facts.objects) or ["object"])[0]
    out["neutral"] = [(t.format(o=alias.get(main, main)), [], None) for t in banks.NEUTRAL]
    return out


def statement_truth(atoms: list[tuple], facts: FrameFacts) -> bool | None:
    if not atoms:
        return None
    truths = [atom_truth(a, facts) for a in atoms]
    if any(t is None for t in truths):
        return None
    return all(truths)


def pick(cands: dict[str, list[tuple]], want: bool | None, facts, rng: random.Random, used=()):
    """A statement of a kind not in `used` whose truth is `want` (None: a neutral one).

    One statement per kind and description, so a description never contradicts itself.
    """
    if want is None:
        return (*rng.choice(cands["neutral"]), None, "neutral")
    kinds = [k for k in cands if k != "neutral" and k not in used]
    rng.shuffle(kinds)
    for k in kinds:
        pool = [c for c in cands[k] if statement_truth(c[1], facts) is want]
        if pool:
            text, atoms, subj = rng.choice(pool)
            return text, atoms, subj, want, k
    return None


def _cap(s: str) -> str:
    return s[:1].upper() + s[1:]


def render(stmts: list[tuple], style: str, rng: random.Random) -> str:
    """Statements (text, atoms, subject, truth) as one description in a model's style."""
    texts = [s[0] for s in stmts]
    # pronouns: a clause about the same object as the one before says "it"
    for i in range(1, len(stmts)):
        subj = stmts[i][2]
        prev_objs = {x for a in stmts[i - 1][1] for x in a[1:] if isinstance(x, str)}
        prev_objs &= set(banks.ALIASES)
        if subj and subj == stmts[i - 1][2] and prev_objs <= {subj} and rng.random() < 0.6:
            m = re.match(r"the ([\w\s'-]+?) (is|has|sits|rests|remains|appears)\b", texts[i])
            agent = re.search(r"gripper|robot|arm|finger", m.group(1)) if m else True
            if m and not agent and m.group(1) in texts[i - 1]:
                texts[i] = "it " + texts[i][m.end(1) + 1 :]
    if style == "gemini-2.5":
        if rng.random() < 0.5:
            head = rng.choice(["**Frame description:** ", "**Observation:** ", ""])
            return head + " ".join(_cap(t) + "." for t in texts)
        lead = rng.choice(["**Scene state:**\n", "Key observations:\n", ""])
        return lead + "\n".join(f"* {_cap(t)}." for t in texts)
    if style == "qwen2.5-vl":
        first = re.sub(r"^the ", "", texts[0]) if rng.random() < 0.5 else texts[0]
        return _cap(", ".join([first] + texts[1:])) + "."
    # gpt-4o: prose, an opener, clauses joined in pairs
    opener = rng.choice(["", "", "In this frame, ", "At this point, ", "Here, ", "In the image, "])
    sentences, i = [], 0
    while i < len(texts):
        if i + 1 < len(texts) and rng.random() < 0.5:
            joiner = rng.choice([", and ", " and ", ", while "])
            sentences.append(texts[i] + joiner + texts[i + 1])
            i += 2
        else:
            sentences.append(texts[i])
            i += 1
    out = [opener + sentences[0] if opener else _cap(sentences[0])]
    out += [_cap(s) for s in sentences[1:]]
    return " ".join(s + "." for s in out)


def describe_frame(facts: FrameFacts, task: str, label: str, style: str, rng: random.Random):
    """A description with the wanted label, or None when the frame cannot give one."""
    cands = candidates(facts, task, rng)
    if label == "true":
        wants = [True] + [True] * rng.randint(0, 1) + [None] * rng.randint(0, 1)
    elif label == "false":
        wants = [False] + [True] * rng.randint(0, 2) + [False] * (rng.random() < 0.2)
    else:
        wants = [None] * rng.randint(1, 2)
    rng.shuffle(wants)
    stmts: list[tuple] = []
    for w in wants:
        s = pick(cands, w, facts, rng, used=[t[4] for t in stmts])
        if s is None:
            return None
        if any(s[0] == t[0] for t in stmts):
            continue
        stmts.append(s)
    n_true = sum(s[3] is True for s in stmts)
    n_false = sum(s[3] is False for s in stmts)
    return (
        render(stmts, style, rng),
        frame_verdict(n_true, n_false),
        [s[0] for s in stmts if s[3] is True],
        [s[0] for s in stmts if s[3] is False],
    )


def _episodes(dirs: list[Path]):
    from rover.io.dataset import load_dataset

    for d in dirs:
        yield from load_dataset(d, load_frames=False)


def build_frames(episodes, rng: random.Random) -> list[dict]:
    cases = []
    for ep in episodes:
        facts = ep.truth.facts
        n = len(facts)
        positions = sorted(rng.sample(range(n), k=min(5, n)))
        for pos in positions:
            for style in STYLES:
                label = rng.choices(["true", "false", "inconclusive"], [0.4, 0.4, 0.2])[0]
                made = describe_frame(facts[pos], ep.task, label, style, rng)
                if made is None:
                    continue
                text, verdict, t_claims, f_claims = made
                cases.append(
                    {
                        "style": style,
                        "episode": ep.id,
                        "frame": pos,
                        "task": ep.task,
                        "family": ep.task_group,
                        "facts": facts[pos].model_dump(mode="json"),
                        "description": text,
                        "label": verdict,
                        "true_claims": t_claims,
                        "false_claims": f_claims,
                    }
                )
    return cases


def hand_cases(episodes) -> list[dict]:
    """The hand-written cases with their frame's task, family and facts filled in."""
    by_id = {ep.id: ep for ep in episodes}
    out = []
    fresh = [{**c, "style": "handwritten-fresh", "force": "heldout"} for c in FRESH_CASES]
    set_a = [{**c, "force": "dev"} for c in SET_A_CASES]
    for c in HAND_FRAMES + set_a + fresh:
        ep = by_id[c["episode"]]
        facts = ep.truth.facts[c["frame"]].model_dump(mode="json")
        out.append({**c, "task": ep.task, "family": ep.task_group, "facts": facts})
    return out


def assign_splits(cases: list[dict], prefix: str, rng: random.Random) -> list[dict]:
    order = list(range(len(cases)))
    rng.shuffle(order)
    forced = {i: c["force"] for i, c in enumerate(cases) if c.get("force")}
    pool = [i for i in order if i not in forced]
    n_dev = len(cases) // 2 - sum(v == "dev" for v in forced.values())
    half = set(pool[:n_dev])
    out = []
    for i, c in enumerate(cases):
        split = forced.get(i) or ("dev" if i in half else "heldout")
        c = {k: v for k, v in c.items() if k != "force"}
        out.append({"id": f"{prefix}{i:04d}", "split": split, **c})
    return out


def main(argv: list[str]) -> None:
    dirs = [Path(a) for a in argv]
    if not dirs:
        raise SystemExit("usage: python -m rover.eval.agreement.build DATASET_DIR [...]")
    rng = random.Random(16)
    episodes = list(_episodes(dirs))
    frames = build_frames(episodes, rng) + hand_cases(episodes)
    from rover.eval.agreement.build_qa import build_qa, hand_qa_cases

    qa = build_qa(episodes, rng) + hand_qa_cases(episodes)
    here = Path(__file__).parent
    for name, cases, prefix, seed in (
        ("frames.json", frames, "f", 1601),
        ("qa.json", qa, "q", 1602),
    ):
        # each file's split has its own seed: adding cases to one never reshuffles the other
        split_rng = random.Random(seed)
        body = {"corpus_version": CORPUS_VERSION, "cases": assign_splits(cases, prefix, split_rng)}
        (here / name).write_text(json.dumps(body, indent=1) + "\n")
        print(f"{name}: {len(cases)} cases")


if __name__ == "__main__":
    main(sys.argv[1:])
