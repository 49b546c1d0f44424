"""Sanity checks for generated ground truth, on `rover.episode` types only.

The generator runs these before writing a dataset, and tests run them on the bundled
dataset, so they must not need MuJoCo. Each check returns human-readable problems
(an empty list means the episode or dataset looks right) rather than raising, so one
report can list everything wrong at once.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Iterable

from rover.episode import Episode, Event, FrameFacts, StateType

HIGHEST_LEVEL_MIN_END = 0.95  # the near-expert level must (almost) finish the task
LEVEL_ORDER_TOLERANCE = 0.1  # neighbouring levels' mean final progress may dip this much


def _holds_or_touches(f: FrameFacts, obj: str) -> bool:
    return f.holding == obj or obj in f.contacts


def _lifted(f: FrameFacts, obj: str) -> bool:
    o = f.objects.get(obj)
    return f.holding == obj or (o is not None and o.lifted)


def _placed(f: FrameFacts, obj: str) -> bool:
    o = f.objects.get(obj)
    if f.holding == obj:
        return False
    return o is None or o.inside not in (None, "start bin") or o.on not in (None, "table")


def _where(f: FrameFacts, obj: str) -> tuple[str | None, str | None] | None:
    o = f.objects.get(obj)
    return None if o is None else (o.inside, o.on)


def _held(f: FrameFacts, obj: str) -> bool:
    return f.holding == obj


def _pressed(f: FrameFacts, obj: str) -> bool:
    return obj in f.pressed or f.articulations.get(obj, 0.0) >= 1.0 - 1e-6


def _opening(f: FrameFacts, obj: str) -> bool:
    return obj not in f.articulations or f.articulations[obj] > 0.0


# frames a released object may take to land in its goal: its place is that frame (read by
# `rover.sim.facts.releases` too; kept here because the audit must not import MuJoCo)
LANDING_FRAMES = 2

# events that mark a hold beginning (True) or ending (False): the frame before must differ
HOLD_CHANGE = {"grasp": True, "drop": False, "place": False}

# event name -> (what must hold at the event frame, wording for the problem message)
EVENT_RULES: dict[str, tuple[Callable[[FrameFacts, str], bool], str]] = {
    "contact": (_holds_or_touches, "the gripper does not touch it"),
    "grasp": (_held, "it is not held"),
    "pick_up": (lambda f, o: _held(f, o) and _lifted(f, o), "it is not held off its start"),
    "drop": (
        lambda f, o: f.holding != o and not (o in f.objects and _placed(f, o)),
        "it is held or in its goal",
    ),
    "place": (_placed, "it is held, or neither inside nor on its goal"),
    "press": (_pressed, "it is not pressed"),
    "open_start": (_opening, "its opening is 0"),
    "open_finish": (_opening, "its opening is 0"),
}


def event_problems(event: Event, facts: list[FrameFacts]) -> list[str]:
    """Whether the facts at an event's frame agree with the event."""
    if event.frame is None or event.object is None:
        return []
    if not 0 <= event.frame < len(facts):
        return [f"event {event.name} {event.object!r} at frame {event.frame} is out of range"]
    rule = EVENT_RULES.get(event.name)
    if rule is None:
        return []
    check, why = rule
    at = facts[event.frame]
    home = _where(at, event.object) == _where(facts[0], event.object)
    if event.name in ("drop", "place") and home:
        # back where it started (a kitchen item on the counter it was taken from, one in
        # the sink it started in): never its goal, whatever that place is called
        check = (lambda f, o: f.holding != o) if event.name == "drop" else (lambda f, o: False)
    if not check(at, event.object):
        return [f"event {event.name} {event.object!r} at frame {event.frame}, but {why} there"]
    begins = HOLD_CHANGE.get(event.name)
    if begins is False and event.frame == 0:
        return [f"event {event.name} {event.object!r} at frame 0 ends a hold no frame shows"]
    if begins is not None and event.frame > 0:
        before = _held(facts[event.frame - 1], event.object)
        if event.name == "place" and not before:  # it may land a few frames after the hold
            lo = max(event.frame - 1 - LANDING_FRAMES, 0)
            before = any(_held(f, event.object) for f in facts[lo : event.frame - 1])
        if before == begins:
            state = "already held" if begins else "not held"
            return [
                f"event {event.name} {event.object!r} at frame {event.frame}, but it was "
                f"{state} the frame before"
            ]
    return []


def validate_episode(episode: Episode, max_level: int | None = None) -> list[str]:
    """Problems with one episode's ground truth (empty list: looks right).

    Args:
        episode: a generated (or bundled) episode.
        max_level: the task's highest level; episodes of that level must end with
            progress >= 0.95. None skips that check.
    """
    truth = episode.truth
    if truth is None:
        return ["no ground truth"]
    n = episode.num_frames
    out: list[str] = []
    prog = truth.progress
    if len(prog) != n:
        out.append(f"{len(prog)} progress values for {n} frames")
    if any(not (math.isfinite(p) and 0.0 <= p <= 1.0) for p in prog):
        out.append("progress must be finite and lie in [0, 1]")
    if prog and truth.progress_source == "simulation" and prog[0] != 0.0:
        out.append(f"progress starts at {prog[0]!r}, expected exactly 0")
    if max_level is not None and truth.level == max_level and prog:
        if prog[-1] < HIGHEST_LEVEL_MIN_END:
            out.append(
                f"highest level {max_level} ends at progress {prog[-1]:.3f} "
                f"< {HIGHEST_LEVEL_MIN_END}"
            )
        drops = [e for e in truth.events if e.name == "drop" and e.frame is not None]
        for e in drops:  # a successful video that "drops" would score a correct model wrong
            out.append(f"highest level {max_level} shows a drop of {e.object!r} at frame {e.frame}")
    if truth.state_type is not None:
        if len(truth.state_type) != n:
            out.append(f"{len(truth.state_type)} state types for {n} frames")
        elif truth.state_type and truth.state_type[0] != StateType.expert:
            out.append("the first frame must be an expert state")
    prev_end = -1
    for s in truth.subtasks:
        if not 0 <= s.start <= s.end < n:
            out.append(f"subtask {s.name!r} spans {s.start}..{s.end}, outside 0..{n - 1}")
        elif s.start <= prev_end:
            out.append(f"subtask {s.name!r} starts at {s.start}, before the previous one ends")
        prev_end = max(prev_end, s.end)
    if truth.facts is not None:
        if len(truth.facts) != n:
            out.append(f"{len(truth.facts)} fact frames for {n} frames")
        else:
            for e in truth.events:
                out.extend(event_problems(e, truth.facts))
    for item in truth.qa:
        if item.frame is not None and not 0 <= item.frame < n:
            out.append(f"QA {item.question!r} points at frame {item.frame}, outside 0..{n - 1}")
        if item.answer is False and item.frame is not None:
            out.append(f"QA {item.question!r} is answered 'no' but has a frame")
    return out


def validate_dataset(episodes: Iterable[Episode]) -> list[str]:
    """Problems across a dataset: every episode, and level ordering per task.

    Within each task, the mean final progress must not fall (beyond a small tolerance)
    as the level rises, and the lowest level must end lower than the highest.
    """
    by_task: dict[str, list[Episode]] = defaultdict(list)
    for ep in episodes:
        by_task[ep.task].append(ep)
    out: list[str] = []
    for task, eps in by_task.items():
        levels = [e.truth.level for e in eps if e.truth is not None and e.truth.level is not None]
        top = max(levels) if levels else None
        for ep in eps:
            out.extend(f"{ep.id}: {p}" for p in validate_episode(ep, max_level=top))
        finals: dict[int, list[float]] = defaultdict(list)
        for ep in eps:
            if ep.truth is not None and ep.truth.level is not None and ep.truth.progress:
                finals[ep.truth.level].append(ep.truth.progress[-1])
        means = {lv: sum(v) / len(v) for lv, v in sorted(finals.items())}
        order = list(means)
        for lo, hi in zip(order, order[1:], strict=False):
            if means[hi] < means[lo] - LEVEL_ORDER_TOLERANCE:
                out.append(
                    f"{task}: level {hi} ends lower on average ({means[hi]:.2f}) "
                    f"than level {lo} ({means[lo]:.2f})"
                )
        if len(order) > 1 and means[order[0]] >= means[order[-1]]:
            out.append(f"{task}: the lowest level ends as high as the highest level")
    return out
