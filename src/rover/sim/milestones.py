"""Level milestones (App. B, Table 5) checked from an episode's own facts and events.

A task lists its components in order, e.g. pick-and-place: approach the can, contact it,
pick it up, keep the grasp while carrying it, bring it over its target, place it. Level
L of a task means: components 1..L-1 achieved, component L not (the top level achieves
all of them). Each component is ``"<kind>:<object>"``:

* ``approach``: the gripper comes within `APPROACH` of the point the object is taken by,
  and at least half way there from where it started;
* ``carry``: the object is held off its start for `CARRY_FRAMES` frames in a row;
* ``approach_goal``: the object, held, is within `APPROACH_GOAL` of its goal in the table
  plane (over its bin, peg or the cube below);
* any event name (``contact``, ``pick_up``, ``place``, ``open_start``, ``press``, ...):
  the event happens in the video.

Everything here reads `rover.episode` types only (no MuJoCo), so the generator's check
and the `rover validate` audit are the same code.
"""

from __future__ import annotations

from collections.abc import Sequence

from rover.episode import Event, FrameFacts

APPROACH = 0.10  # m from the gripper to the grip point that counts as "approached"
APPROACH_GOAL = 0.08  # m (table plane) from a held object to its goal: "over the target"
CARRY_FRAMES = 4  # consecutive frames held and lifted that count as "kept the grasp"


def achieved(component: str, facts: Sequence[FrameFacts], events: Sequence[Event]) -> bool:
    """Whether the video shows one component (see the module docstring for the kinds)."""
    kind, _, obj = component.partition(":")
    if kind == "approach":
        reach = [o.reach for f in facts if (o := f.objects.get(obj)) and o.reach is not None]
        if not reach:
            return False
        # within APPROACH, and at least half way from where the gripper started (a part
        # that starts 12 cm from the hand is not "approached" by standing still)
        return min(reach) <= min(APPROACH, 0.5 * reach[0])
    if kind == "carry":
        run = 0
        for f in facts:
            o = f.objects.get(obj)
            run = run + 1 if f.holding == obj and o is not None and o.lifted else 0
            if run >= CARRY_FRAMES:
                return True
        return False
    if kind == "approach_goal":
        return any(
            f.holding == obj
            and (o := f.objects.get(obj)) is not None
            and o.goal_distance is not None
            and o.goal_distance <= APPROACH_GOAL
            for f in facts
        )
    if kind == "place":  # placed, or let fall and come to rest in its goal all the same
        # (a region other than the one it starts in: a kitchen item leaving the sink
        # for the counter starts "inside" the sink, which is not its goal)
        start = _where(facts[0], obj) if facts else None
        return any(_in_goal(f, obj) and _where(f, obj) != start for f in facts) or _event(
            kind, obj, events
        )
    return _event(kind, obj, events)


def _event(kind: str, obj: str, events: Sequence[Event]) -> bool:
    return any(e.name == kind and e.object == obj and e.frame is not None for e in events)


def _where(f: FrameFacts, obj: str) -> tuple[str | None, str | None] | None:
    o = f.objects.get(obj)
    return None if o is None else (o.inside, o.on)


def _in_goal(f: FrameFacts, obj: str) -> bool:
    o = f.objects.get(obj)
    if o is None or f.holding == obj:
        return False
    return o.inside not in (None, "start bin") or o.on not in (None, "table")


def level_problems(
    level: int,
    components: Sequence[str],
    facts: Sequence[FrameFacts],
    events: Sequence[Event],
) -> list[str]:
    """Why an episode does not show its level (empty: it does).

    Level L needs components 1..L-1 and must not show component L.
    """
    out: list[str] = []
    need = list(components[: max(level - 1, 0)])
    for c in need:
        if not achieved(c, facts, events):
            out.append(f"level {level} needs {c!r}, which the video never shows")
    if level - 1 < len(components):
        nxt = components[level - 1]
        if achieved(nxt, facts, events):
            out.append(f"level {level} must stop before {nxt!r}, but the video shows it")
    return out
