"""One verified try at an episode, and the expert demo trimming it starts from.

`make_attempt` perturbs a demo at the episode's level, computes progress, picks the
video's frames and reads their facts and events, all without rendering, then checks
the result against the level's milestone (`rover.sim.milestones`) and against physics
(no object jumps where a recovery hands back to the expert). The generator retries with
a new seed offset until an attempt passes, so resampling costs simulation only; only the
accepted attempt is rendered.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field

import numpy as np

from rover.episode import Event, FrameFacts, even_positions
from rover.sim.levels import LevelSpec, plan_seed
from rover.sim.milestones import level_problems
from rover.sim.tasks.base import TaskSpec

MAX_TRIES = 12  # tries per episode before the best one is kept (and flagged)
ENDINGS = 6  # final deviations drawn per planned prefix
FLOOR_TOLERANCE = 0.05  # (no milestone marks) a level may end this far below the level under it
TRY_STRIDE = 1_000_003  # plan index offset between attempts (independent Generators)
RECOVERY_GAP = 0.015  # m an object may sit off the expert state a recovery hands over to
HIGHEST_MIN_END = 0.95  # the top level must (almost) finish the task
IDLE_KEEP = 2  # idle steps kept in a row (a short pause reads as a pause, not a stall)
RETREAT_KEEP = 12  # expert steps kept after the task is done (the hand backs off)


_MARKS: dict[str, dict] = {}  # task -> (demo, length, crc) -> ExpertMarks, per process


def trim_demo(
    sim, states: np.ndarray, actions: np.ndarray, ends: list[int]
) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """Drop the expert's idle and creeping steps and the end of its retreat.

    Scripted experts pause (fingers closing, settling, the final hold), slow down at the
    end of every reach, and back off for a while once the task is done; sampled evenly
    (densely, in a short video), those stretches become runs of frames in which nothing
    visibly changes. A step is idle when, since the last kept step, nothing changes by
    the audit's own test (`rover.sim.audit.facts_changed`: hand, objects, gripper
    opening, joints), so what the trim keeps is exactly what the audit calls motion; at
    most `IDLE_KEEP` idle steps in a row are kept, and `RETREAT_KEEP` steps after the
    last subtask's end. Subtask-end steps are always kept; ends are remapped.
    """
    from rover.sim.audit import facts_changed
    from rover.sim.facts import facts_for_states

    n = len(states)
    last = min(n - 1, int(ends[-1]) + RETREAT_KEEP) if ends else n - 1
    must = set(int(e) for e in ends) | {0, last}
    saved = sim.get_state()
    facts = facts_for_states(sim, states[: last + 1])
    sim.set_state(saved)
    keep = [0]
    idle = 0
    for t in range(1, last + 1):
        if facts_changed(facts[keep[-1]], facts[t]):
            keep.append(t)
            idle = 0
        elif t in must:  # a still subtask end: kept, in place of the last still step
            if idle >= IDLE_KEEP and keep[-1] not in must:
                keep.pop()
            keep.append(t)
            idle = min(idle + 1, IDLE_KEEP)
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
    marks: dict | None = None,
):
    """Yield measured tries at an episode until the caller stops (at most `MAX_TRIES`).

    A try is a plan (seeded by ``index`` plus an offset per plan) rolled out up to its
    final, unrecovered deviation, which is then drawn afresh up to `ENDINGS` times: the
    ending decides most milestones ("contact, but not picked up") and costs a few dozen
    steps, while the prefix (expert path and recovered deviations) is simulated once.
    A prefix whose recovery would make an object jump is replanned at once.

    Levels with a ``milestone_cut`` leave the expert inside the stretch of the demo
    between its last component and its next one (`rover.sim.cuts`); ``marks`` caches
    each demo's `ExpertMarks` across episodes (default: this process's cache per task,
    keyed by the demo's index and a checksum of its states).
    """
    from dataclasses import replace

    from rover.sim.cuts import cut_window, draw_cut, held_contact_window, progress_band
    from rover.sim.facts import detect_events, facts_for_states
    from rover.sim.perturb import (
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
    marks = _MARKS.setdefault(spec.name, {}) if marks is None else marks
    tries = 0
    plan_no = 0
    while tries < MAX_TRIES:
        rng = plan_seed(seed, spec.name, index + plan_no * TRY_STRIDE)
        plan_no += 1
        usable = _usable_demos(sim, spec, level, demos, marks, frames)
        d = int(usable[int(rng.integers(len(usable)))])
        states, actions, ends, demo_seed = demos[d]
        sim.reset(demo_seed)  # places robosuite's visual-only markers as in the demo's scene
        sim.begin(states[0])  # start positions (lift heights, goals) of this demo
        bounds = bounds_from_ends(ends, len(states))
        key = _demo_key(d, states)
        if d not in expert_tracks:
            expert_tracks[d] = point_tracks(sim, states, names)
        pkey = ("progress", key, form)
        if pkey not in marks:  # the expert's own progress per step
            steps = np.arange(len(states))
            marks[pkey] = progress_from_tracks(
                expert_tracks[d], steps, expert_tracks[d], spec.subtasks, bounds,
                goal_end=int(ends[-1]), form=form,  # type: ignore[arg-type]
            )  # fmt: skip
        window = cut_window(level, spec.milestones, marks[key], frames)
        held = None
        if window is None:  # a demo whose hold starts with its contact
            window = held = held_contact_window(level, spec.milestones, marks[key])
        band = None
        if window is not None:  # cut by milestone: the level's own band
            band = progress_band(level, spec.milestones, marks[key], marks[pkey])
            if held is None:
                window = within_band(window, marks[pkey], band)
                window = _touching(sim, spec, level, states, window, marks, key)
        if band is None:  # no milestone marks: the level below's subtask fraction
            band = (_floor(below, marks[pkey], bounds), 1.0)
        cut = draw_cut(window, level, rng) if window is not None else None
        plan = plan_trajectory(
            len(states), bounds, level, rng, cut=cut, deviate_before=window and window[0]
        )
        act_rng = np.random.default_rng(rng.integers(2**63))
        terminal = plan.segments[-1] if plan.terminated else None
        if terminal is not None:
            drift = level.terminal_drift if any(level.terminal_drift) else None
            terminal = replace(terminal, grip=_grip(level, actions, terminal.q), drift=drift)
            lo, hi = level.terminal_settle
            if hi > 0:  # lowered in the grasp first (its own draw: other levels unchanged)
                settle = int(rng.integers(lo, hi + 1))
                terminal = replace(terminal, w=terminal.w + settle, settle=settle)
        head = replace(plan, segments=plan.segments[:-1]) if terminal is not None else plan
        prefix = execute_plan(sim, states, actions, head, act_rng)
        pre_tracks = point_tracks(sim, prefix.states, names, signals)
        endings = ENDINGS if terminal is not None else 1
        for e in range(endings):
            tries += 1
            roll, tracks = prefix, pre_tracks
            if terminal is not None:
                seg = terminal
                if e:  # a fresh ending, each a little gentler than the last
                    w = int(rng.integers(level.terminal_w[0], level.terminal_w[1] + 1))
                    seg = replace(
                        seg,
                        w=w + seg.settle,
                        scale=seg.scale * 0.8**e,
                        hold=min(seg.hold, w),
                        depth=0,
                    )
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
            if terminal is not None:
                pos = snap_position(pos, len(prefix) - 1)
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
            if terminal is not None and not band[0] <= prog[-1] <= band[1]:
                problems.append(
                    f"ends at progress {prog[-1]:.2f}, outside its level's band "
                    f"{band[0]:.2f}..{band[1]:.2f} (`rover.sim.cuts.progress_band`)"
                )
            if level.level == top and prog[-1] < HIGHEST_MIN_END:
                problems.append(f"top level ends at progress {prog[-1]:.2f} < {HIGHEST_MIN_END}")
            if level.level == top:  # the audit's rule: a successful video never "drops"
                problems += [
                    f"top level shows a drop of {e.object!r} at frame {e.frame}"
                    for e in events
                    if e.name == "drop" and e.frame is not None
                ]
            yield Attempt(tries, d, roll, prog, pos, facts, events, problems)
            if roll.recovery_gap > RECOVERY_GAP or tries >= MAX_TRIES:
                break  # the prefix itself is at fault: plan again
            if problems and _prefix_shows_next(spec, level, facts, pos, len(prefix)):
                break  # (a recovered deviation did it: no ending can take it back)


def within_band(
    window: tuple[int, int], expert: np.ndarray, band: tuple[float, float] | None
) -> tuple[int, int]:
    """The part of a cut window whose expert steps lie inside the level's progress band.

    The window is drawn by milestone steps, but expert progress is not linear in steps
    (the hand creeps the last centimetres to a handle): a cut late in the "approached,
    not touched" stretch could already stand above that level's ceiling, and every
    ending drawn from it failed the band. Cutting where the expert itself is in the band
    makes the level constructive rather than found by resampling. The whole window when
    no step of it is in the band (the band check then decides, as before).
    """
    if band is None:
        return window
    lo, hi = window
    ok = [t for t in range(lo, hi + 1) if band[0] <= float(expert[t]) <= band[1]]
    return (ok[0], ok[-1]) if ok else window


def _touching(sim, spec: TaskSpec, level: LevelSpec, states, window, marks: dict, key):
    """A level that follows a "contact" component leaves the expert at a step where the
    fingers touch the object, when the window has such steps.

    The expert's first touch is often a brush (a finger grazes the drawer's bar on the
    way down, then loses it until the fingers close), so a cut drawn anywhere after it
    could fall where nothing touches, and the video, whose frames missed the brush,
    never showed the contact its level needs.
    """
    L = level.level
    if L < 2 or L - 2 >= len(spec.milestones):
        return window
    kind, _, obj = spec.milestones[L - 2].partition(":")
    if kind != "contact":
        return window
    tkey = ("touch", key, obj)
    if tkey not in marks:
        saved = sim.get_state()
        touch = []
        for s in states:
            sim.set_state(s)
            touch.append(obj in sim.finger_contacts())
        sim.set_state(saved)
        marks[tkey] = np.asarray(touch, dtype=bool)
    lo, hi = window
    ok = np.flatnonzero(marks[tkey][lo : hi + 1]) + lo
    return (int(ok[0]), int(ok[-1])) if len(ok) else window


def _prefix_shows_next(spec: TaskSpec, level: LevelSpec, facts, pos, n_prefix: int) -> bool:
    """Whether the video's frames before the final deviation already show the level's
    next component (a recovered deviation pushed the door ajar): redrawing the ending
    cannot help, so the try plans afresh."""
    from rover.sim.facts import detect_events
    from rover.sim.milestones import achieved

    if level.completes or level.level - 1 >= len(spec.milestones):
        return False
    k = sum(1 for p in pos if p < n_prefix)
    head = list(facts[:k])
    nxt = spec.milestones[level.level - 1]
    return bool(head) and achieved(nxt, head, detect_events(spec, head))


def _demo_key(d: int, states: np.ndarray) -> tuple[int, int, int]:
    return (d, len(states), zlib.crc32(np.ascontiguousarray(states).tobytes()))


def _usable_demos(sim, spec: TaskSpec, level: LevelSpec, demos: list, marks: dict, frames: int):
    """The demos in which a level can be cut by milestone (else those it can be cut at
    a held contact, `rover.sim.cuts.held_contact_window`; all of them when neither, or
    the level does not cut by milestone): a Stack demo that grasps the red cube already
    within reach of the green one shows "over the target" before "carry", so its L5
    stretch is empty."""
    from rover.sim.cuts import cut_window, held_contact_window

    ok, held = [], []
    for d, (states, _, _, demo_seed) in enumerate(demos):
        key = _demo_key(d, states)
        if key not in marks:
            sim.reset(demo_seed)
            sim.begin(states[0])
            marks[key] = demo_marks(sim, spec, states)
        if level.milestone_cut is None or cut_window(level, spec.milestones, marks[key], frames):
            ok.append(d)
        elif held_contact_window(level, spec.milestones, marks[key]):
            held.append(d)
    return ok or held or list(range(len(demos)))


def snap_position(pos: list[int], step: int) -> list[int]:
    """Move the sampled position nearest to `step` onto it (first and last stay).

    The step where a video leaves the expert is what its level shows (the fingers on
    the can, the can just lifted): even sampling may fall either side of it, so the
    nearest frame moves there, at most half a frame interval off even spacing.
    """
    if step in pos or len(pos) < 3:
        return pos
    k = min(range(1, len(pos) - 1), key=lambda i: abs(pos[i] - step))
    if pos[k - 1] < step < pos[k + 1]:
        pos = list(pos)
        pos[k] = step
    return pos


def _grip(level: LevelSpec, actions: np.ndarray, q: int) -> float | None:
    """The gripper command of a level's final deviation (None: random)."""
    if level.terminal_grip == "open":
        return -1.0
    if level.terminal_grip == "close":
        return 1.0
    if level.terminal_grip == "keep" and len(actions):
        return float(actions[min(int(q), len(actions) - 1)][-1])
    return None


def demo_marks(sim, spec: TaskSpec, states: np.ndarray):
    """`ExpertMarks` of one expert demo, from the facts of every step (the simulator must
    be reset to the demo's scene; no rendering). Each step's "moves with the hand" is
    judged against the step before, as in a video's facts."""
    from rover.sim.cuts import expert_marks
    from rover.sim.facts import facts_for_states

    saved = sim.get_state()
    prev = states[np.maximum(np.arange(len(states)) - 1, 0)]
    facts = facts_for_states(sim, states, prev)
    sim.set_state(saved)
    return expert_marks(spec, facts)


def _floor(below, expert_progress: np.ndarray, bounds) -> float:
    """Without milestone marks: the expert's progress in the middle of the level below's
    subtask fraction, less `FLOOR_TOLERANCE` (0 with no terminating level below)."""
    if below is None or below.terminate_subtask is None:
        return 0.0
    k = min(below.terminate_subtask, len(bounds) - 1)
    a, b = bounds[k]
    cut = a + int(round(sum(below.terminate_at) / 2 * (b - a)))
    return max(float(expert_progress[cut]) - FLOOR_TOLERANCE, 0.0)
