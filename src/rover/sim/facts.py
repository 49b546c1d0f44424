"""Per-frame simulator facts, the events they imply, and templated video-QA items.

Facts are read from MuJoCo for exactly the frames a video shows, and events are derived
from that same fact sequence (the first frame where the facts change in the named way),
so facts and events can never disagree: an event's frame always shows it. QA items
(App. C.3) are answered from the events: "yes, at frame t" or "no".
"""

from __future__ import annotations

import numpy as np

from rover.episode import Event, FrameFacts, ObjectFacts, QAItem
from rover.sim import articulation
from rover.sim.env import SimEnv
from rover.sim.tasks.base import TaskSpec

CLOSED_BELOW = 0.9  # opening fraction under which the gripper reads as closed
OPEN_START = 0.05  # door opening fraction at which "start opening" happens
OPEN_FINISH = 0.9  # ... and "completely open"


def frame_facts(sim: SimEnv) -> FrameFacts:
    """Facts of the simulator's current state."""
    spec = sim.spec
    touching = sim.finger_contacts()
    opening = sim.gripper_opening()
    holding = None
    objects: dict[str, ObjectFacts] = {}
    articulations: dict[str, float] = {}
    distances: dict[str, float] = {}
    eef = sim.point("eef")
    for obj in spec.objects:
        pos = sim.point(obj.name)
        both = touching.get(obj.name) == {"left", "right"}
        lifted = obj.graspable and sim.lifted(obj.name)
        if both and (lifted or not obj.graspable):
            holding = obj.name
        objects[obj.name] = ObjectFacts(
            position=tuple(round(float(x), 4) for x in pos),
            lifted=bool(lifted),
            inside=_inside(sim, obj.name),
            on=_on(sim, obj.name, lifted, both),
        )
        distances[f"gripper-{obj.name}"] = round(float(np.linalg.norm(eef - pos)), 4)
    if "door_open" in spec.goals:
        frac = sim.hinge_angle() / spec.goals["door_open"].angle
        articulations["door"] = round(float(np.clip(frac, 0.0, 1.0)), 3)
    fixture_parts, pressed = articulation.articulation_facts(sim)
    articulations.update(fixture_parts)
    if holding is not None and not articulation.holdable(sim, holding):
        holding = None  # a fingertip on a push button is not a hold
    return FrameFacts(
        gripper="closed" if opening < CLOSED_BELOW else "open",
        gripper_opening=round(opening, 3),
        contacts=sorted(touching),
        holding=holding,
        objects=objects,
        articulations=articulations,
        pressed=pressed,
        distances=distances,
    )


def _inside(sim: SimEnv, obj: str) -> str | None:
    if not sim.spec.object_spec(obj).graspable:
        return None
    if hasattr(sim.env, "not_in_bin"):  # robosuite PickPlace: the four target compartments
        idx = sim.in_bin(obj)
        if idx is not None:
            return f"bin {idx + 1}"
        pos, src, half = sim.point(obj), sim.env.bin1_pos, np.asarray(sim.env.bin_size) / 2
        if np.all(np.abs(pos[:2] - src[:2]) < half[:2]) and pos[2] < src[2] + 0.1:
            return "start bin"  # the bin all items start in
        return None
    if "peg" in sim.spec.goals and sim.on_peg(obj):
        return "peg"
    return None


def _on(sim: SimEnv, obj: str, lifted: bool, held: bool) -> str | None:
    spec = sim.spec
    if not spec.object_spec(obj).graspable or lifted or held or _inside(sim, obj):
        return None
    for other in spec.objects:
        if other.name != obj and other.graspable and sim.on_top(obj, other.name):
            return other.name
    start = sim.start_positions.get(obj)
    if start is not None and abs(sim.point(obj)[2] - start[2]) < 0.02:
        return "table"
    return None


def facts_for_states(sim: SimEnv, states: np.ndarray) -> list[FrameFacts]:
    """Facts of each state in order (sets the simulator's state)."""
    out = []
    for s in states:
        sim.set_state(s)
        out.append(frame_facts(sim))
    return out


def _first(facts: list[FrameFacts], test, after: int = 0) -> int | None:
    for t in range(after, len(facts)):
        if test(facts[t]):
            return t
    return None


def _target_reached(spec: TaskSpec, obj: str, f: FrameFacts) -> bool:
    o = f.objects.get(obj)
    if o is None or f.holding == obj:
        return False
    if obj in spec.bins:
        return o.inside == f"bin {spec.bins[obj] + 1}"
    if "peg" in spec.goals:
        return o.inside == "peg"
    if "on" in spec.goals:
        return o.on == spec.goals["on"].object
    return False


def detect_events(spec: TaskSpec, facts: list[FrameFacts]) -> list[Event]:
    """Events implied by the fact sequence; expected events that never happen get None."""
    events: list[Event] = []
    for obj in spec.objects:
        name = obj.name
        if not any(q.object == name for q in spec.qa_templates) and not any(
            s.object == name for s in spec.subtasks
        ):
            continue
        contact = _first(facts, lambda f, n=name: n in f.contacts)
        events.append(Event(name="contact", object=name, frame=contact))
        if obj.graspable:
            grasp = _first(facts, lambda f, n=name: f.holding == n or _both(f, n))
            pick = _first(facts, lambda f, n=name: f.holding == n and f.objects[n].lifted)
            events.append(Event(name="grasp", object=name, frame=grasp))
            events.append(Event(name="pick_up", object=name, frame=pick))
            drop = place = None
            if pick is not None:
                place = _first(facts, lambda f, n=name: _target_reached(spec, n, f), pick)
                drop = _first(
                    facts,
                    lambda f, n=name: f.holding != n and not _target_reached(spec, n, f),
                    pick,
                )
                if drop is not None and place is not None and drop > place:
                    drop = None
            events.append(Event(name="drop", object=name, frame=drop))
            if spec.bins or "on" in spec.goals or "peg" in spec.goals:
                events.append(Event(name="place", object=name, frame=place))
        elif name == "door":
            events.append(
                Event(name="grasp", object=name, frame=_first(facts, lambda f: f.holding == "door"))
            )
            events.append(
                Event(
                    name="open_start",
                    object=name,
                    frame=_first(facts, lambda f: f.articulations.get("door", 0.0) >= OPEN_START),
                )
            )
            events.append(
                Event(
                    name="open_finish",
                    object=name,
                    frame=_first(facts, lambda f: f.articulations.get("door", 0.0) >= OPEN_FINISH),
                )
            )
        elif name in articulation.PARTS:
            events += articulation.fixture_events(spec, name, facts)
    return events


def _both(f: FrameFacts, name: str) -> bool:
    # grasp = touched while the gripper is closed on it (holding also needs a lift)
    return name in f.contacts and f.gripper == "closed"


def qa_items(spec: TaskSpec, events: list[Event]) -> list[QAItem]:
    """Answer every QA template of the task from the events."""
    found = {(e.name, e.object): e.frame for e in events}
    out = []
    for tpl in spec.qa_templates:
        frame = found.get((tpl.event, tpl.object))
        out.append(
            QAItem(
                question=tpl.text,
                answer=frame is not None,
                frame=frame,
                template=tpl.id,
                event=tpl.event,
                object=tpl.object,
            )
        )
    return out
