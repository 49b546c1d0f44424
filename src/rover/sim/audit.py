"""The dataset audit behind `rover validate`: does the truth match what the video shows?

Per task it counts, over every episode: whether the episode shows its level's milestone
and not the next one (`rover.sim.milestones`), whether each event agrees with the facts
at its frame (`rover.sim.validate.event_problems`), whether an object nothing touches
rises between two frames (a teleport: physics only lets free objects fall), the mean
final progress of each level (must not fall as the level rises), and expert stalls (more
than `STALL_FRAMES` expert frames in a row where nothing changes). It reads
`rover.episode` types only, so it runs on any dataset without MuJoCo.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field

from rover.episode import Episode, FrameFacts, StateType
from rover.sim.milestones import level_problems
from rover.sim.validate import validate_episode

RISE = 0.02  # m an untouched object may not rise between two frames
STALL_FRAMES = 3  # expert frames in a row without change that count as a stall
STILL_PROGRESS = 0.01  # progress change per frame below which progress is flat ...
STILL_POS = 0.005  # ... and no hand or object moves more than this (m) ...
STILL_GRIP = 0.02  # ... nor does the gripper open or close more than this
ORDER_TOLERANCE = 1e-6  # mean final progress may not fall from one level to the next
# progress an articulated part must add while it moves start -> goal, in a task of
# `JOINT_SUBTASKS` subtasks (an atomic fixture task: grasp or reach, then turn or press);
# a task of n subtasks needs JOINT_GAIN * JOINT_SUBTASKS / n (`joint_gain_needed`)
JOINT_GAIN = 0.25
JOINT_SUBTASKS = 2
JOINT_START, JOINT_FINISH = 0.1, 0.9  # the part's fraction of the way: "moving" between


@dataclass
class TaskAudit:
    """What the audit found for one task."""

    task: str
    episodes: int = 0
    milestones_met: int = 0
    events_ok: int = 0
    untouched_moved: int = 0  # episodes where an untouched object rises between frames
    stalls: int = 0  # episodes with an expert stall
    joint_lags: int = 0  # episodes whose progress does not rise while a part moves
    finals: dict[int, list[float]] = field(default_factory=lambda: defaultdict(list))
    tries: dict[int, list[int]] = field(default_factory=lambda: defaultdict(list))
    problems: list[str] = field(default_factory=list)

    def level_means(self) -> dict[int, float]:
        return {lv: sum(v) / len(v) for lv, v in sorted(self.finals.items())}

    def ordered(self) -> bool:
        means = list(self.level_means().values())
        return all(b >= a - ORDER_TOLERANCE for a, b in zip(means, means[1:], strict=False))

    @property
    def failed(self) -> bool:
        return bool(self.problems)


def untouched_rises(facts: list[FrameFacts]) -> list[str]:
    """Objects that rise more than `RISE` between frames while nothing of the robot
    touches them in either frame (and they are not held)."""
    out = []
    for t in range(1, len(facts)):
        a, b = facts[t - 1], facts[t]
        for name, ob in b.objects.items():
            oa = a.objects.get(name)
            if oa is None or oa.position is None or ob.position is None:
                continue
            touched = (
                name in a.robot_contacts
                or name in b.robot_contacts
                or name in a.contacts
                or name in b.contacts
                or name in (a.holding, b.holding)
            )
            rise = ob.position[2] - oa.position[2]
            if rise > RISE and not touched:
                out.append(f"untouched {name!r} rises {rise * 100:.1f} cm at frame {t}")
    return out


def facts_changed(a: FrameFacts, b: FrameFacts) -> bool:
    """Whether anything visible changes from frame `a` to frame `b`: the hand or an
    object moves more than `STILL_POS`, the gripper opens or closes more than
    `STILL_GRIP`, or a joint turns more than `STILL_GRIP` of its range. The expert trim
    (`rover.sim.attempt.trim_demo`) keeps steps by this same test."""
    if a.eef is not None and b.eef is not None:
        if max(abs(x - y) for x, y in zip(a.eef, b.eef, strict=True)) > STILL_POS:
            return True
    if a.gripper_opening is not None and b.gripper_opening is not None:
        if abs(a.gripper_opening - b.gripper_opening) > STILL_GRIP:
            return True
    for name, ob in b.objects.items():
        oa = a.objects.get(name)
        if oa is not None and oa.position and ob.position:
            if max(abs(x - y) for x, y in zip(oa.position, ob.position, strict=True)) > STILL_POS:
                return True
    return any(abs(v - a.articulations.get(k, v)) > STILL_GRIP for k, v in b.articulations.items())


def joint_gain_needed(subtasks: int) -> float:
    """Progress a part's motion must earn in a task of `subtasks` subtasks.

    Progress is shared among the subtasks, so the part's subtask carries about 1/n of
    it: in an atomic fixture task (two subtasks) the turn must earn `JOINT_GAIN`, half
    of its share; in a composite whose sixth subtask turns the faucet lever, the whole
    turn is worth about 1/6 and half of that is asked (PreSoakPan's turn earns 0.15)."""
    return JOINT_GAIN * JOINT_SUBTASKS / max(subtasks, JOINT_SUBTASKS)


def joint_lags(
    facts: list[FrameFacts], progress: list[float], subtasks: int = JOINT_SUBTASKS
) -> list[str]:
    """Articulated parts that go from their start to their goal while progress gains less
    than `joint_gain_needed` for a task of `subtasks` subtasks: progress must follow the
    joint (a knob's turn, a door's swing), not jump when the hand lets go. The way
    toward the goal is read from the first frame (a part starting above half way, an
    open drawer to close, is measured by 1 - fraction);
    the gain is taken from the last frame at most `JOINT_START` of the way to the first
    frame at least `JOINT_FINISH` of it. A part that goes the whole way between two
    consecutive frames (a button's click) is skipped: there is no motion in the video for
    progress to follow, and what the press subtask earned before it (the finger coming
    down onto the button) is honest progress."""
    out = []
    if not facts or len(progress) != len(facts):
        return out
    need = joint_gain_needed(subtasks)
    for name, first in facts[0].articulations.items():
        way = [
            (1.0 - v if first > 0.5 else v)
            for v in (f.articulations.get(name, first) for f in facts)
        ]
        done = next((t for t, w in enumerate(way) if w >= JOINT_FINISH), None)
        if done is None:
            continue
        start = next((t for t in range(done - 1, -1, -1) if way[t] <= JOINT_START), None)
        if start is None or done - start < 2:
            continue  # (a part that clicks between two sampled frames has no way to follow)
        gain = progress[done] - progress[start]
        if gain < need:
            out.append(
                f"progress gains {gain:.2f} < {need:.2f} while the {name} moves to its goal "
                f"(frames {start}-{done})"
            )
    return out


def _changed(a: FrameFacts, b: FrameFacts, pa: float, pb: float) -> bool:
    return abs(pb - pa) >= STILL_PROGRESS or facts_changed(a, b)


def expert_stalls(episode: Episode) -> list[str]:
    """Runs of more than `STALL_FRAMES` expert frames in which nothing changes."""
    truth = episode.truth
    if truth is None or truth.facts is None or truth.state_type is None:
        return []
    out = []
    run = 1
    for t in range(1, episode.num_frames):
        expert = truth.state_type[t] == truth.state_type[t - 1] == StateType.expert
        still = expert and not _changed(
            truth.facts[t - 1], truth.facts[t], truth.progress[t - 1], truth.progress[t]
        )
        run = run + 1 if still else 1
        if run == STALL_FRAMES + 1:
            out.append(f"expert stalls for {run} frames ending at frame {t}")
    return out


def _spec(episode: Episode):
    """The rover task an episode was generated from; None for any other dataset."""
    task = episode.extra.get("sim_task")
    if not task:
        return None
    from rover.sim.tasks import get_task

    try:
        return get_task(task)
    except Exception:  # noqa: BLE001 - a dataset from another rover version: skip the check
        return None


def _components(episode: Episode) -> list[str] | None:
    spec = _spec(episode)
    return None if spec is None else spec.milestones


def _subtask_count(episode: Episode) -> int:
    """Subtasks of the episode's task: its spec's, else the ones its truth lists."""
    spec = _spec(episode)
    if spec is not None:
        return len(spec.subtasks)
    return len(episode.truth.subtasks) if episode.truth is not None else JOINT_SUBTASKS


def audit(episodes: Iterable[Episode]) -> list[TaskAudit]:
    """Audit every episode; one `TaskAudit` per task, in first-seen order."""
    eps = list(episodes)
    tops: dict[str, int] = defaultdict(int)
    for ep in eps:
        if ep.truth is not None and ep.truth.level is not None:
            tops[_task_key(ep)] = max(tops[_task_key(ep)], ep.truth.level)
    for key in tops:  # the task's own top level, when rover knows the task
        spec_top = _top_level(key)
        if spec_top is not None:
            tops[key] = spec_top
    out: dict[str, TaskAudit] = {}
    for ep in eps:
        key = _task_key(ep)
        ta = out.setdefault(key, TaskAudit(key))
        ta.episodes += 1
        truth = ep.truth
        base = validate_episode(ep, max_level=tops.get(key))
        ta.problems += [f"{ep.id}: {p}" for p in base]
        if truth is None:
            continue
        facts = truth.facts or []
        comps = _components(ep)
        if comps is not None and truth.level is not None and facts:
            why = level_problems(truth.level, comps, facts, truth.events)
            if why:
                ta.problems += [f"{ep.id}: {p}" for p in why]
            else:
                ta.milestones_met += 1
        if not any(p.startswith("event ") for p in base):  # validate_episode checks events
            ta.events_ok += 1
        rises = untouched_rises(facts)
        if rises:
            ta.untouched_moved += 1
            ta.problems += [f"{ep.id}: {p}" for p in rises]
        lags = joint_lags(facts, list(truth.progress), _subtask_count(ep))
        if lags:
            ta.joint_lags += 1
            ta.problems += [f"{ep.id}: {p}" for p in lags]
        stalls = expert_stalls(ep)
        if stalls:
            ta.stalls += 1
            ta.problems += [f"{ep.id}: {p}" for p in stalls]
        if truth.level is not None and truth.progress:
            ta.finals[truth.level].append(truth.progress[-1])
            ta.tries[truth.level].append(int(ep.extra.get("tries", 1)))
    for ta in out.values():
        if not ta.ordered():
            means = " ".join(f"L{lv} {m:.2f}" for lv, m in ta.level_means().items())
            ta.problems.append(f"{ta.task}: mean final progress falls with level ({means})")
    return list(out.values())


def _top_level(task: str) -> int | None:
    from rover.sim.tasks import get_task

    try:
        return max(lv.level for lv in get_task(task).levels)
    except Exception:  # noqa: BLE001 - not a rover task
        return None


def _task_key(ep: Episode) -> str:
    return str(ep.extra.get("sim_task") or ep.task)
