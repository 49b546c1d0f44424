"""Per-frame simulator facts, the events they imply, and templated video-QA items.

Facts are read from MuJoCo for exactly the frames a video shows, and events are derived
from that same fact sequence (the first frame where the facts change in the named way),
so facts and events can never disagree: an event's frame always shows it. QA items
(App. C.3) are answered from the events: "yes, at frame t" or "no".

Holding is physical, not a height test: the robot holds an object when both fingers
touch it and it moves with the gripper (its position in the hand's frame is unchanged
since the previous control step), at any height. A hold, once begun, survives a frame
where one finger loses contact for a moment, as long as the object still moves with the
hand. Events follow from holds: ``grasp`` is a hold beginning, ``pick_up`` a held object
first lifted off its start, and a hold's end is a ``place`` when the object is then
resting in or on its goal region and a ``drop`` otherwise (it falls). An object let go a
few centimetres above its goal is still falling at the frame the hold ends (a cereal box
reads "on the table" for the one frame it passes the bin's rim height): the place is the
frame it lands in the goal, if that is within `LANDING_FRAMES` frames and before any new
hold.
"""

from __future__ import annotations

import numpy as np

from rover.episode import Event, FrameFacts, ObjectFacts, QAItem
from rover.sim import articulation
from rover.sim.env import SimEnv
from rover.sim.tasks.base import TaskSpec
from rover.sim.validate import LANDING_FRAMES

CLOSED_BELOW = 0.9  # opening fraction under which the gripper reads as closed
OPEN_START = 0.05  # door opening fraction at which "start opening" happens
OPEN_FINISH = 0.9  # ... and "completely open"
MOVES_WITH = 0.005  # m: the most a held object may shift in the hand's frame per step
FULLY_OPEN = 0.97  # opening fraction above which fingers touching both sides only brush it
STOOD = 0.015  # m: a held object that moves less than this was never taken anywhere


def grip_point(spec: TaskSpec, obj: str) -> str:
    """The named point the hand takes an object by: its first subtask's contact point."""
    for s in spec.subtasks:
        if s.object == obj and s.object_points:
            return s.object_points[0]
    return obj


def goal_point(spec: TaskSpec, obj: str) -> str | None:
    """The goal point an object is carried to (the last subtask on it with a goal)."""
    found = None
    for s in spec.subtasks:
        if s.object == obj and s.goal is not None:
            found = s.goal
    return found


def hand_positions(sim: SimEnv) -> dict[str, np.ndarray]:
    """Each object's grip point in the end effector's frame (for the moves-with test)."""
    pos, rot = sim.eef_frame()
    return {
        o.name: rot.T @ (sim.point(grip_point(sim.spec, o.name)) - pos) for o in sim.spec.objects
    }


def frame_facts(
    sim: SimEnv,
    before: dict[str, np.ndarray] | None = None,
    held_before: str | None = None,
) -> FrameFacts:
    """Facts of the simulator's current state.

    Args:
        sim: the simulator, posed at the state to describe.
        before: `hand_positions` one control step earlier (None: the object is taken to
            move with the hand, as at an episode's first frame).
        held_before: the object held at the previous video frame (keeps a hold through
            a one-frame loss of one finger's contact).
    """
    spec = sim.spec
    touching = sim.finger_contacts()
    robot_touch = sim.robot_contacts()
    opening = sim.gripper_opening()
    now = hand_positions(sim)
    holding = None
    objects: dict[str, ObjectFacts] = {}
    distances: dict[str, float] = {}
    eef = sim.point("eef")
    for obj in spec.objects:
        name = obj.name
        pos = sim.point(name)
        fingers = touching.get(name, set())
        moves = before is None or float(np.linalg.norm(now[name] - before[name])) < MOVES_WITH
        both = fingers == {"left", "right"} and opening < FULLY_OPEN
        kept = held_before == name and bool(fingers)
        if (both or kept) and moves and articulation.holdable(sim, name) and holding is None:
            holding = name
        goal = goal_point(spec, name)
        goal_dist = None
        if goal is not None and obj.graspable:
            goal_dist = round(float(np.linalg.norm((pos - sim.point(goal))[:2])), 4)
        lifted = obj.graspable and sim.lifted(name)
        objects[name] = ObjectFacts(
            position=tuple(round(float(x), 4) for x in pos),
            lifted=bool(lifted),
            inside=_inside(sim, name),
            on=_on(sim, name, lifted, holding == name),
            reach=round(float(np.linalg.norm(eef - sim.point(grip_point(spec, name)))), 4),
            goal_distance=goal_dist,
        )
        distances[f"gripper-{name}"] = round(float(np.linalg.norm(eef - pos)), 4)
    articulations: dict[str, float] = {}
    if "door_open" in spec.goals:
        frac = sim.hinge_angle() / spec.goals["door_open"].angle
        articulations["door"] = round(float(np.clip(frac, 0.0, 1.0)), 3)
    fixture_parts, pressed = articulation.articulation_facts(sim)
    articulations.update(fixture_parts)
    return FrameFacts(
        gripper="closed" if opening < CLOSED_BELOW else "open",
        gripper_opening=round(opening, 3),
        contacts=sorted(touching),
        holding=holding,
        objects=objects,
        articulations=articulations,
        pressed=pressed,
        distances=distances,
        eef=tuple(round(float(x), 4) for x in eef),
        robot_contacts=sorted(robot_touch),
    )


def _inside(sim: SimEnv, obj: str) -> str | None:
    if not sim.spec.object_spec(obj).graspable:
        return None
    place = _kitchen_place(sim, obj)
    if place is not None:  # a kitchen item: the region it rests in (sink basin, ...)
        return place[1] if place[0] == "inside" else None
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


def _kitchen_place(sim: SimEnv, obj: str) -> tuple[str, str] | None:
    """A kitchen pick-and-place item's (relation, region); None elsewhere or when loose."""
    per_item = getattr(sim.env, "object_place", None)
    if per_item is not None:  # a kitchen composite: each of its items has its own place
        return per_item(obj)
    where = getattr(sim.env, "item_place", None)
    return where() if where is not None else None


def _on(sim: SimEnv, obj: str, lifted: bool, held: bool) -> str | None:
    spec = sim.spec
    if not spec.object_spec(obj).graspable or held or _inside(sim, obj):
        return None
    kitchen = getattr(sim.env, "item_category", None) or hasattr(sim.env, "object_place")
    if kitchen:  # a kitchen item: the surface region only
        place = _kitchen_place(sim, obj)
        return place[1] if place is not None and place[0] == "on" else None
    for other in spec.objects:
        if other.name != obj and other.graspable and sim.on_top(obj, other.name):
            return other.name
    start = sim.start_positions.get(obj)
    if start is not None and abs(sim.point(obj)[2] - start[2]) < 0.02:
        return "table"
    return None


def facts_for_states(
    sim: SimEnv, states: np.ndarray, previous: np.ndarray | None = None
) -> list[FrameFacts]:
    """Facts of each state in order (sets the simulator's state).

    Args:
        sim: the simulator.
        states: (N, S) the video's states.
        previous: (N, S) the state one control step before each (None: the previous
            video frame; pass the rollout's step t-1 so "moves with the hand" is judged
            over one step, as physics would).
    """
    out: list[FrameFacts] = []
    prev_hand: dict[str, np.ndarray] | None = None
    held: str | None = None
    for t, s in enumerate(states):
        if previous is not None:
            sim.set_state(previous[t])
            prev_hand = hand_positions(sim)
        sim.set_state(s)
        f = frame_facts(sim, prev_hand, held)
        out.append(f)
        held = f.holding
        if previous is None:
            prev_hand = hand_positions(sim)
    return out


def _first(facts: list[FrameFacts], test, after: int = 0) -> int | None:
    for t in range(after, len(facts)):
        if test(facts[t]):
            return t
    return None


def target_reached(spec: TaskSpec, obj: str, f: FrameFacts) -> bool:
    o = f.objects.get(obj)
    if o is None or f.holding == obj:
        return False
    if obj in spec.bins:
        return o.inside == f"bin {spec.bins[obj] + 1}"
    if "peg" in spec.goals:
        return o.inside == "peg"
    if "on" in spec.goals:
        return o.on == spec.goals["on"].object
    region = goal_region(spec, obj)
    if region is not None:  # a kitchen composite's item: its own goal region
        return region in (o.inside, o.on)
    if "region" in spec.goals:  # a kitchen goal region, named in the env's arguments
        return spec.env_kwargs.get("goal") in (o.inside, o.on)
    return False


def goal_region(spec: TaskSpec, obj: str) -> str | None:
    """The region a kitchen composite's item goes to (its env arguments' ``items`` rows:
    name, category, start, goal); None for any other object or task."""
    for row in spec.env_kwargs.get("items", ()):
        if row[0] == obj:
            return str(row[3])
    return None


def hold_spans(facts: list[FrameFacts], obj: str) -> list[tuple[int, int | None]]:
    """(first held frame, first frame after the hold or None) for each hold of `obj`."""
    spans: list[tuple[int, int | None]] = []
    start = None
    for t, f in enumerate(facts):
        if f.holding == obj and start is None:
            start = t
        elif f.holding != obj and start is not None:
            spans.append((start, t))
            start = None
    if start is not None:
        spans.append((start, None))
    return spans


def _stood(facts: list[FrameFacts], obj: str, start: int, end: int) -> bool:
    """Whether `obj` stays within `STOOD` of where it stood the frame before a hold took
    it, unlifted, up to the frame after the hold."""
    first = facts[max(start - 1, 0)].objects.get(obj)
    if first is None or first.position is None:
        return False
    p0 = np.asarray(first.position)
    for f in facts[start : end + 1]:
        o = f.objects.get(obj)
        if o is None or o.position is None or o.lifted:
            return False
        if np.linalg.norm(np.asarray(o.position) - p0) > STOOD:
            return False
    return True


def releases(spec: TaskSpec, facts: list[FrameFacts], obj: str) -> list[tuple[str, int]]:
    """("place" | "drop", frame) for each hold of `obj` that ends, in order.

    A hold ends at the first frame the object is not held; it is a place (at the frame
    it lands) when the object rests in or on its goal region there or within
    `LANDING_FRAMES` frames after, before any new hold; else a drop, at the hold's end.
    A hold in which the object never moves (fingers closed on it, then opened) is
    neither: it was let go where it stood, and did not fall (`STOOD`).
    """
    out: list[tuple[str, int]] = []
    spans = hold_spans(facts, obj)
    for i, (start, end) in enumerate(spans):
        if end is None:
            continue
        if _stood(facts, obj, start, end):
            continue
        regrip = spans[i + 1][0] if i + 1 < len(spans) else len(facts)
        last = min(end + LANDING_FRAMES, regrip - 1)
        land = next((t for t in range(end, last + 1) if target_reached(spec, obj, facts[t])), None)
        out.append(("drop", end) if land is None else ("place", land))
    return out


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
            spans = hold_spans(facts, name)
            grasp = spans[0][0] if spans else None
            pick = _first(facts, lambda f, n=name: f.holding == n and f.objects[n].lifted)
            events.append(Event(name="grasp", object=name, frame=grasp))
            events.append(Event(name="pick_up", object=name, frame=pick))
            ends = releases(spec, facts, name)
            drop = next((t for kind, t in ends if kind == "drop"), None)
            place = next((t for kind, t in ends if kind == "place"), None)
            events.append(Event(name="drop", object=name, frame=drop))
            goals = ("on", "peg", "region")
            if spec.bins or any(g in spec.goals for g in goals) or goal_region(spec, name):
                events.append(Event(name="place", object=name, frame=place))
        elif name == "door" and not articulation.closing(spec, name):
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
