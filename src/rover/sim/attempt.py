"""One verified try at an episode, and the expert demo trimming it starts from.

`make_attempt` perturbs a demo at the episode's level, computes progress, picks the
video's frames and reads their facts and events, all without rendering, then checks
the result against the level's milestone (`rover.sim.milestones`) and against physics
(no object jumps where a recovery hands back to the expert). The generator retries with
a new seed offset until an attempt passes, so resampling costs simulation only; only the
accepted attempt is rendered.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rover.episode import Event, FrameFacts, even_positions
from rover.sim.levels import LevelSpec, plan_seed
from rover.sim.milestones import level_problems
from rover.sim.tasks.base import TaskSpec

MAX_TRIES = 12  # tries per episode before the best one is kept (and flagged)
ENDINGS = 6  # final deviations drawn per planned prefix
FLOOR_TOLERANCE = 0.05  # a level may end this far below the previous level's cut
TRY_STRIDE = 1_000_003  # plan index offset between attempts (independent Generators)
RECOVERY_GAP = 0.015  # m an object may sit off the expert state a recovery hands over to
HIGHEST_MIN_END = 0.95  # the top level must (almost) finish the task
IDLE_POS = 0.002  # m: an expert step that moves no entity more than this is idle ...
IDLE_GRIP = 0.01  # ... and changes the gripper opening less than this ...
IDLE_JOINT = 0.01  # ... and no articulated joint (knob, drawer) moves this fraction of its range
IDLE_KEEP = 2  # idle steps kept in a row (a short pause reads as a pause, not a stall)
RETREAT_KEEP = 12  # expert steps kept after the task is done (the hand backs off)


def trim_demo(
    sim, states: np.ndarray, actions: np.ndarray, ends: list[int]
) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """Drop the expert's idle steps and the end of its retreat.

    Scripted experts pause (fingers closing, settling, the final hold) and back off for a
    while once the task is done; sampled evenly, those stretches become runs of identical
    frames. A step is idle when no entity (hand, objects) moves more than `IDLE_POS` and
    the gripper opening changes less than `IDLE_GRIP` and no subtask joint more than
    `IDLE_JOINT` since the last kept step; at most `IDLE_KEEP` idle steps in a row are
    kept, and `RETREAT_KEEP` steps after the last subtask's end. Subtask-end steps are
    always kept; ends are remapped.
    """
    n = len(states)
    last = min(n - 1, int(ends[-1]) + RETREAT_KEEP) if ends else n - 1
    must = set(int(e) for e in ends) | {0, last}
    ents, grip, arts = [], [], []
    # a knob turns on its axis (no point of it moves): its joint is watched as well
    joints = sorted({s.joint for s in sim.spec.subtasks if getattr(s, "joint", None)})
    saved = sim.get_state()
    for s in states[: last + 1]:
        sim.set_state(s)
        ents.append(sim.entity_positions())
        grip.append(sim.gripper_opening())
        arts.append(np.asarray([sim.point(j)[0] for j in joints], dtype=np.float64))
    sim.set_state(saved)
    keep = [0]
    idle = 0
    for t in range(1, last + 1):
        ref = keep[-1]
        moved = float(np.abs(ents[t] - ents[ref]).max()) > IDLE_POS
        gripped = abs(grip[t] - grip[ref]) > IDLE_GRIP
        turned = bool(joints) and float(np.abs(arts[t] - arts[ref]).max()) > IDLE_JOINT
        if moved or gripped or turned or t in must:
            keep.append(t)
            idle = 0
        elif idle < IDLE_KEEP:
            keep.append(t)
            idle += 1
    idx = np.asarray(keep)
    new_ends = [int(np.searchsorted(idx, e)) for e in ends]
    acts = actions[idx] if len(actions) == n else actions[np.minimum(idx, len(actions) - 1)]
    return states[idx], acts, new_ends


@dataclass
class Attempt:
    """A rolled-out, measured, not yet rendered episode candidate."""

    tries: int
    demo: int
    roll: object
    progress: np.ndarray  # per sampled frame, in [0, 1]
    positions: list[int]
    facts: list[FrameFacts]
    events: list[Event]
    problems: list[str] = field(default_factory=list)


def _join(a, b):
    """One Rollout from a prefix and the terminal deviation executed after it."""
    from rover.sim.perturb import Rollout

    return Rollout(
        states=np.concatenate([a.states, b.states]),
        q=np.concatenate([a.q, b.q]),
        j=np.concatenate([a.j, b.j]),
        z=np.concatenate([a.z, b.z]),
        depth=np.concatenate([a.depth, b.depth]),
        state_type=list(a.state_type) + list(b.state_type),
        subtask=np.concatenate([a.subtask, b.subtask]),
        terminated=b.terminated,
        plan=a.plan,
        recovery_gap=a.recovery_gap,
    )


def _join_tracks(a, b):
    from rover.sim.value import Tracks

    return Tracks(
        {k: np.concatenate([v, b.points[k]]) for k, v in a.points.items()},
        np.concatenate([a.entities, b.entities]),
        {k: np.concatenate([v, b.kept[k]]) for k, v in a.kept.items()},
    )


def make_attempts(
    sim,
    spec: TaskSpec,
    level: LevelSpec,
    demos: list,
    expert_tracks: dict,
    seed: int,
    index: int,
    frames: int,
    form: str = "rover",
):
    """Yield measured tries at an episode until the caller stops (at most `MAX_TRIES`).

    A try is a plan (seeded by ``index`` plus an offset per plan) rolled out up to its
    final, unrecovered deviation, which is then drawn afresh up to `ENDINGS` times: the
    ending decides most milestones ("contact, but not picked up") and costs a few dozen
    steps, while the prefix (expert path and recovered deviations) is simulated once.
    A prefix whose recovery would make an object jump is replanned at once.
    """
    from dataclasses import replace

    from rover.sim.facts import detect_events, facts_for_states
    from rover.sim.perturb import (
        RandomSegment,
        TrajectoryPlan,
        bounds_from_ends,
        execute_plan,
        plan_trajectory,
    )
    from rover.sim.value import point_tracks, progress_from_tracks, required_points

    names = required_points(spec.subtasks)
    signals = [s.end_signal for s in spec.subtasks]
    top = max(lv.level for lv in spec.levels)
    below = next((lv for lv in spec.levels if lv.level == level.level - 1), None)
    tries = 0
    plan_no = 0
    while tries < MAX_TRIES:
        rng = plan_seed(seed, spec.name, index + plan_no * TRY_STRIDE)
        plan_no += 1
        d = int(rng.integers(len(demos)))
        states, actions, ends, demo_seed = demos[d]
        sim.reset(demo_seed)  # places robosuite's visual-only markers as in the demo's scene
        sim.begin(states[0])  # start positions (lift heights, goals) of this demo
        bounds = bounds_from_ends(ends, len(states))
        plan = plan_trajectory(len(states), bounds, level, rng)
        act_rng = np.random.default_rng(rng.integers(2**63))
        terminal = plan.segments[-1] if plan.terminated else None
        head = replace(plan, segments=plan.segments[:-1]) if terminal is not None else plan
        prefix = execute_plan(sim, states, actions, head, act_rng)
        if d not in expert_tracks:
            expert_tracks[d] = point_tracks(sim, states, names)
        floor = _floor(below, expert_tracks[d], spec, bounds, int(ends[-1]), form)
        pre_tracks = point_tracks(sim, prefix.states, names, signals)
        endings = ENDINGS if terminal is not None else 1
        for e in range(endings):
            tries += 1
            roll, tracks = prefix, pre_tracks
            if terminal is not None:
                seg = terminal
                if e:  # a fresh ending, each a little gentler than the last
                    w = int(rng.integers(level.terminal_w[0], level.terminal_w[1] + 1))
                    seg = RandomSegment(seg.q, w, seg.scale * 0.8**e, min(seg.hold, w), 0)
                tail_plan = TrajectoryPlan(
                    plan.expert_len, plan.subtask_bounds, (seg,), plan.level, True
                )
                tail = execute_plan(sim, states, actions, tail_plan, act_rng)
                roll = _join(prefix, tail)
                tracks = _join_tracks(pre_tracks, point_tracks(sim, tail.states, names, signals))
            progress = progress_from_tracks(
                tracks,
                roll.q,
                expert_tracks[d],
                spec.subtasks,
                bounds,
                goal_end=int(ends[-1]),
                form=form,  # type: ignore[arg-type]
            )
            pos = even_positions(len(roll), frames)
            prev = roll.states[np.maximum(np.asarray(pos) - 1, 0)]
            facts = facts_for_states(sim, roll.states[pos], prev)
            events = detect_events(spec, facts)
            prog = np.clip(np.asarray(progress)[pos], 0.0, 1.0)
            prog[0] = 0.0
            problems = level_problems(level.level, spec.milestones, facts, events)
            if roll.recovery_gap > RECOVERY_GAP:
                problems.append(
                    f"a recovery leaves an object {roll.recovery_gap * 100:.1f} cm off the "
                    "expert state it hands over to (it would jump)"
                )
            if terminal is not None and prog[-1] < floor:
                problems.append(
                    f"ends at progress {prog[-1]:.2f}, below where the level under it stops "
                    f"({floor + FLOOR_TOLERANCE:.2f})"
                )
            if level.level == top and prog[-1] < HIGHEST_MIN_END:
                problems.append(f"top level ends at progress {prog[-1]:.2f} < {HIGHEST_MIN_END}")
            yield Attempt(tries, d, roll, prog, pos, facts, events, problems)
            if roll.recovery_gap > RECOVERY_GAP or tries >= MAX_TRIES:
                break  # the prefix itself is at fault: plan again


def _floor(below, expert, spec: TaskSpec, bounds, goal_end: int, form: str) -> float:
    """The expert's progress where the level below stops (its cut point's middle), less
    `FLOOR_TOLERANCE`: a level's video must end at least that far along, so the final
    progress rises with the level (0 when there is no terminating level below)."""
    from rover.sim.value import progress_from_tracks

    if below is None or below.terminate_subtask is None:
        return 0.0
    k = min(below.terminate_subtask, len(bounds) - 1)
    a, b = bounds[k]
    cut = a + int(round(sum(below.terminate_at) / 2 * (b - a)))
    steps = np.arange(len(expert))
    prog = progress_from_tracks(
        expert, steps, expert, spec.subtasks, bounds, goal_end=goal_end, form=form
    )
    return max(float(prog[cut]) - FLOOR_TOLERANCE, 0.0)
