"""The rule QA answerer's reading of descriptions: what each frame asserts, and when an
event is first asserted.

Each description is reduced to the state it claims (what is held, touched, lifted, where
objects are, how open a part is, what is pressed); an event is then a predicate over that
claimed state and, for "drop", over the previous frames' (held before, released now,
not put where the task's "place" question says it goes).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from rover.episode import QAItem
from rover.eval.claim_names import names_match, normalise_name
from rover.eval.claims import extract_claims
from rover.eval.rule_judge import CLOSED_MAX, FULLY_OPEN_MIN, OPEN_MIN, _target

_DROP_WORDS = re.compile(r"\b(drop(?:s|ped|ping)?|fell|falls|falling|slip(?:s|ped|ping)?)\b", re.I)


@dataclass
class Asserted:
    """What one frame description claims about the scene."""

    text: str = ""
    gripper: str | None = None  # "open" / "closed" when the description says
    held: set[str] = field(default_factory=set)
    released: bool = False  # "not holding anything" / "gripper is empty"
    not_held: set[str] = field(default_factory=set)
    dropped: set[str] = field(default_factory=set)  # "drops the can", "the can slips out"
    touched: set[str] = field(default_factory=set)
    lifted: dict[str, bool] = field(default_factory=dict)
    inside: dict[str, str] = field(default_factory=dict)  # object -> place, as said
    on: dict[str, str] = field(default_factory=dict)
    # articulation as the range of fractions the words allow: "closed" (0, 0.1),
    # "partly open" (0.1, 0.9), "fully open" (0.9, 1), "about 40% open" (0.4, 0.4)
    parts: dict[str, tuple[float, float]] = field(default_factory=dict)
    pressed: dict[str, bool] = field(default_factory=dict)


_STATE_RANGE = {
    "open": (OPEN_MIN + 1e-6, 1.0),
    "closed": (0.0, CLOSED_MAX),
    "fully_open": (FULLY_OPEN_MIN, 1.0),
    "not_fully_open": (0.0, FULLY_OPEN_MIN - 1e-6),
    "partly_open": (OPEN_MIN + 1e-6, FULLY_OPEN_MIN - 1e-6),
    "partly_closed": (CLOSED_MAX + 1e-6, FULLY_OPEN_MIN - 1e-6),
}


def _resolve_place(said: str, obj: str, task: str | None) -> str:
    """ "the target bin" -> the task's bin for `obj`; other places as said."""
    return _target(said, obj, task) or said


def asserted_states(descriptions: list[str | None], task: str | None = None) -> list[Asserted]:
    """One `Asserted` per frame position (`task` says which bin "the target bin" is)."""
    out = []
    for d in descriptions:
        a = Asserted(text=d or "")
        for c in extract_claims(d):
            s = c.subject or ""
            if c.kind == "gripper":
                a.gripper = str(c.value)
            elif c.kind == "holding":
                (a.held.add if c.value else a.not_held.add)(s)
                if not c.value and _DROP_WORDS.search(c.text):
                    a.dropped.add(s)
            elif c.kind == "holding_any":
                a.released = a.released or not c.value
            elif c.kind == "contact" and c.value:
                a.touched.add(s)
            elif c.kind == "lifted":
                a.lifted[s] = bool(c.value)
            elif c.kind == "at_start" and c.value:
                a.lifted.setdefault(s, False)
            elif c.kind in ("inside", "on"):
                target, positive = c.value  # type: ignore[misc]
                if normalise_name(target) in ("table", "tabletop", "surface", "counter"):
                    if positive:
                        a.lifted.setdefault(s, False)
                elif positive:
                    place = _resolve_place(target, s, task) if c.kind == "inside" else target
                    (a.inside if c.kind == "inside" else a.on)[s] = place
            elif c.kind == "articulation_pct":
                v = float(c.value)  # type: ignore[arg-type]
                a.parts[s] = (v, v)
            elif c.kind == "articulation" and str(c.value) in _STATE_RANGE:
                a.parts[s] = _STATE_RANGE[str(c.value)]
            elif c.kind == "pressed":
                a.pressed[s] = bool(c.value)
        out.append(a)
    return out


_EVENT_FROM_TEXT = [
    (r"start\w*\s+open", "open_start"),
    (r"start\w*\s+clos", "close_start"),
    (r"start\w*\s+turn", "turn_start"),
    (r"complete\w*\s+open", "open_finish"),
    (r"complete\w*\s+clos", "close_finish"),
    (r"turn\w*\s+on\b|complete\w*\s+turn\s+on", "turn_on"),
    (r"turn\w*\s+off\b|complete\w*\s+turn\s+off", "turn_off"),
    (r"\bcontact", "contact"),
    (r"\bpick\w*\s+up", "pick_up"),
    (r"\bdrop", "drop"),
    (r"\bplace|\bput", "place"),
    (r"\bgrasp|\bgrab", "grasp"),
    (r"\bpress|\bpush", "press"),
    (r"\bopen", "open_finish"),
    (r"\bclose", "close_finish"),
]
_OBJ_FROM_TEXT = re.compile(
    r"did the robot (?:\w+\s+){0,3}?(?:the|a)\s+(.+?)(?:\s+(?:in|into|on|onto)\s+.+)?\?", re.I
)
_TARGET_FROM_TEXT = re.compile(r"\s(?:in|into|on|onto)\s+(?:the\s+)?(.+?)\?", re.I)


def event_of(item: QAItem) -> str:
    """The event a question asks about: its `event` field, else read from the question."""
    name = (item.event or "").lower().replace("-", "_").replace(" ", "_")
    if name:
        return {
            "pick": "pick_up",
            "pickup": "pick_up",
            "lift": "pick_up",
            "touch": "contact",
            "open": "open_finish",
            "close": "close_finish",
        }.get(name, name)
    for pat, ev in _EVENT_FROM_TEXT:
        if re.search(pat, item.question, re.I):
            return ev
    return "unknown"


def object_of(item: QAItem) -> str:
    if item.object:
        return item.object
    m = _OBJ_FROM_TEXT.search(item.question)
    return m.group(1) if m else ""


def place_target(item: QAItem) -> str | None:
    m = _TARGET_FROM_TEXT.search(item.question)
    return m.group(1).strip() if m else None


def _has(names: set[str] | dict, obj: str) -> bool:
    return any(names_match(n, obj) for n in names)


def _get(d: dict[str, object], obj: str) -> object | None:
    for k, v in d.items():
        if names_match(k, obj):
            return v
    return None


def first_event_position(item: QAItem, states: list[Asserted], qa: list[QAItem]) -> int | None:
    """Position of the first frame whose description asserts the event (None: never)."""
    ev, obj = event_of(item), object_of(item)
    target = place_target(item) if ev == "place" else None
    if ev == "drop":
        places = [
            place_target(q) for q in qa if event_of(q) == "place" and names_match(object_of(q), obj)
        ]
        target = next((p for p in places if p), None)
    was_held = False
    for pos, a in enumerate(states):
        held_now = _has(a.held, obj)
        if _event_here(ev, obj, target, a, was_held):
            return pos
        if held_now:
            was_held = True
        elif a.released or _has(a.not_held, obj):
            was_held = False
    return None


def _event_here(ev: str, obj: str, target: str | None, a: Asserted, was_held: bool) -> bool:
    if ev == "contact":
        return _has(a.touched, obj) or _has(a.held, obj)
    if ev == "grasp":
        # held, or the gripper closed while touching it (how the simulator defines a grasp)
        return _has(a.held, obj) or (a.gripper == "closed" and _has(a.touched, obj))
    if ev == "pick_up":  # lifted, said outright or by a lifting verb ("picks up the can")
        return _get(a.lifted, obj) is True
    if ev == "place":
        where = _get(a.inside, obj) or _get(a.on, obj)
        return where is not None and (target is None or names_match(str(where), target))
    if ev == "drop":
        if _has(a.dropped, obj):
            return True
        released = a.released or _has(a.not_held, obj)
        where = _get(a.inside, obj) or _get(a.on, obj)
        placed = where is not None and (target is None or names_match(str(where), target))
        return was_held and released and not placed
    if ev == "press":
        return _get(a.pressed, obj) is True
    if ev in ("turn_on", "turn_off"):
        # an appliance switched by a push button: "on" is said as the button being pressed
        pressed = _get(a.pressed, obj)
        if pressed is None and obj != "button":
            pressed = _get(a.pressed, "button")
        if pressed is not None:  # a pressed stop button (the kitchen microwave's) is "off"
            return pressed is (ev == ("turn_off" if obj == "stop button" else "turn_on"))
    rng = _get(a.parts, obj)
    if not isinstance(rng, tuple):
        return False
    lo, hi = rng
    if ev in ("open_start", "turn_start"):
        return lo > OPEN_MIN
    if ev == "close_start":
        return hi < FULLY_OPEN_MIN
    if ev in ("open_finish", "turn_on", "turn_finish"):
        return lo >= FULLY_OPEN_MIN
    if ev in ("close_finish", "turn_off"):
        return hi <= CLOSED_MAX
    return False
