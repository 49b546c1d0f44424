"""Ground-truth progress values for generated trajectories (paper Sec. 4.2, App. N).

Every formula is a small pure numpy function over point tracks (positions of named points
per step), so each can be checked by hand; `progress_from_tracks` sequences them and
`ground_truth_value` measures the tracks in a simulator first. Notation follows the paper:

* ``y_t = (1 - beta) * sum_j ||p^{r_j}_t - p^{l_j}_t|| + beta * ||p^e_t - p^e_f||``
  (goal-focused distance, `goal_distance`);
* keypoints ``kappa``: local maxima of ``y`` along the expert subtask (`keypoints`), plus
  the subtask's last expert step so that a next keypoint always exists;
* ``u_t = ||s_t - s^E_{k_next}||``, ``k_next = min{k in kappa | k > q_t}`` over the full
  entity state (`trajectory_distance`), optionally plus the expert's remaining keypoint
  path so u does not jump when the expert passes a keypoint;
* ``d = y + u``, ``v = (max d - d) / (max d - min d)`` with the expert subtask's range
  (`normalise`), chained over subtasks (`chain_subtasks`) and rescaled so the start is 0
  and the expert's end is 1 (`rescale_from_start`). See docs/ground_truth.md.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np

from rover.sim.adapter import SimAdapter

KEYPOINT_PROMINENCE = 0.1  # fraction of the subtask's y range a local maximum must stand out
# a joint's whole way to its goal weighs at least as much as this much hand travel (m):
# a knob tip's quarter turn moves 3 cm and a button's 1 cm, so the hand's distance
# would otherwise swamp the joint in any state off the expert's path
JOINT_SPAN_MIN = 0.10


class SubtaskLike(Protocol):
    """The fields of `rover.sim.tasks.base.SubtaskSpec` the value needs."""

    object: str
    robot_points: list[str]
    object_points: list[str]
    goal: str | None
    beta: float
    end_signal: str
    joint: str | None


@dataclass
class Tracks:
    """Named point positions per step, plus the full entity state per step."""

    points: dict[str, np.ndarray]  # name -> (N, 3)
    entities: np.ndarray  # (N, B, 3): end effector first, then every task object
    # end signal -> (N,) whether that subtask's achievement still stands at each step
    kept: dict[str, np.ndarray] = field(default_factory=dict)
    # end signal -> (N,) whether the state meets the signal itself (the subtask's end test)
    reached: dict[str, np.ndarray] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.entities.shape[0])

    def take(self, idx: np.ndarray) -> Tracks:
        """The tracks at the given step indices."""
        return Tracks(
            {k: v[idx] for k, v in self.points.items()},
            self.entities[idx],
            {k: v[idx] for k, v in self.kept.items()},
            {k: v[idx] for k, v in self.reached.items()},
        )


def required_points(subtasks: Iterable[SubtaskLike]) -> list[str]:
    """Every named point the subtasks' distances read, in first-use order."""
    names: dict[str, None] = {}
    for s in subtasks:
        for n in [*s.robot_points, *s.object_points, s.object]:
            names[n] = None
        if s.goal is not None:
            names[s.goal] = None
        if getattr(s, "joint", None):
            names[s.joint] = None
    return list(names)


def point_tracks(
    adapter: SimAdapter, states: np.ndarray, names: Sequence[str], signals: Sequence[str] = ()
) -> Tracks:
    """Measure named points and entity positions in each state (restores the current state).

    ``signals``: subtask end signals whose standing (``adapter.kept``) and whose end test
    (``adapter.predicate``) are recorded per step, for the undo and reach rules of
    `progress_from_tracks`; adapters without ``kept`` skip both.
    """
    saved = adapter.get_state()
    pts: dict[str, list[np.ndarray]] = {n: [] for n in names}
    ents: list[np.ndarray] = []
    kept_fn = getattr(adapter, "kept", None)
    test_fn = getattr(adapter, "predicate", None)
    signals = list(signals) if kept_fn is not None else []
    kept: dict[str, list[bool]] = {s: [] for s in signals}
    reached: dict[str, list[bool]] = {s: [] for s in signals if test_fn is not None}
    try:
        for s in np.asarray(states):
            adapter.set_state(s)
            for n in names:
                pts[n].append(np.asarray(adapter.point(n), dtype=np.float64))
            ents.append(np.asarray(adapter.entity_positions(), dtype=np.float64))
            for sig in signals:
                kept[sig].append(bool(kept_fn(sig)))
            for sig in reached:
                reached[sig].append(bool(test_fn(sig)))
    finally:
        adapter.set_state(saved)
    return Tracks(
        {n: np.stack(v) for n, v in pts.items()},
        np.stack(ents),
        {k: np.asarray(v, dtype=bool) for k, v in kept.items()},
        {k: np.asarray(v, dtype=bool) for k, v in reached.items()},
    )


# ---------------------------------------------------------------- formulas
def goal_distance(
    robot: np.ndarray,
    obj_contacts: np.ndarray,
    obj: np.ndarray | None,
    goal: np.ndarray | None,
    beta: float,
) -> np.ndarray:
    """Goal-focused distance y_t = (1 - beta) y^{r,e}_t + beta y^{e,f}_t.

    Args:
        robot: (N, C, 3) robot contact points r_j.
        obj_contacts: (N, C, 3) matching object contact points l_j.
        obj: (N, 3) target object position p^e (None when the subtask has no goal).
        goal: (N, 3) goal position p^e_f (None: no goal term, y = y^{r,e}).
        beta: weight of the goal term in [0, 1].

    Returns:
        (N,) distances.
    """
    y_re = np.linalg.norm(np.asarray(robot) - np.asarray(obj_contacts), axis=-1).sum(axis=-1)
    if goal is None or obj is None:
        return y_re
    y_ef = np.linalg.norm(np.asarray(obj) - np.asarray(goal), axis=-1)
    return (1.0 - beta) * y_re + beta * y_ef


def keypoints(y: np.ndarray, min_prominence: float = KEYPOINT_PROMINENCE) -> np.ndarray:
    """Indices of the local maxima of y that stand out by ``min_prominence`` of its range.

    Without a prominence threshold, simulator jitter on a flat stretch would turn every
    wiggle into a keypoint. Prominence is the classic one: height above the higher of
    the lowest points on each side before y rises above the peak again. Plateaus count
    once, at their first step; the first and last steps are never keypoints.
    """
    y = np.asarray(y, dtype=np.float64)
    n = len(y)
    span = float(y.max() - y.min()) if n else 0.0
    out: list[int] = []
    t = 1
    while t < n - 1:
        if y[t] > y[t - 1]:
            e = t
            while e + 1 < n and y[e + 1] == y[t]:
                e += 1
            if e < n - 1 and y[e + 1] < y[t]:
                left = t
                while left > 0 and y[left - 1] <= y[t]:
                    left -= 1
                right = e
                while right < n - 1 and y[right + 1] <= y[t]:
                    right += 1
                base = max(y[left : t + 1].min(), y[e : right + 1].min())
                if y[t] - base >= min_prominence * span and y[t] - base > 0:
                    out.append(t)
            t = e + 1
        else:
            t += 1
    return np.asarray(out, dtype=np.int64)


def next_keypoint(q: np.ndarray, kappa: np.ndarray, last: int) -> np.ndarray:
    """k_next = min{k in kappa | k > q}; ``last`` (the subtask's end) when none is left."""
    kap = np.sort(np.append(np.asarray(kappa, dtype=np.int64), last))
    pos = np.searchsorted(kap, np.asarray(q), side="right")
    return kap[np.minimum(pos, len(kap) - 1)]


def trajectory_distance(
    entities: np.ndarray,
    expert_entities: np.ndarray,
    k_next: np.ndarray,
    kappa: np.ndarray | None = None,
    last: int | None = None,
) -> np.ndarray:
    """u_t = ||s_t - s^E_{k_next}||_2 over the flattened (B, 3) entity state.

    With ``kappa`` and ``last`` given, adds the expert's remaining path through the later
    keypoints, ``sum ||s^E_{k_a} - s^E_{k_b}||`` over consecutive keypoints after k_next.
    The paper's u alone jumps up when q passes a keypoint (the target switches to a
    farther one), which makes even the expert's value dip; the remaining path keeps u
    continuous along the expert while leaving off-expert states farther away.

    Args:
        entities: (N, B, 3) rollout entity positions.
        expert_entities: (T, B, 3) expert entity positions, indexed by expert step.
        k_next: (N,) expert index of each step's next keypoint.
        kappa: subtask keypoints (expert indices); None for the paper's plain u.
        last: the subtask's last expert index (always the final keypoint).
    """
    ent = np.asarray(entities, dtype=np.float64).reshape(len(k_next), -1)
    exp = np.asarray(expert_entities, dtype=np.float64)
    exp = exp.reshape(exp.shape[0], -1)
    u = np.linalg.norm(ent - exp[k_next], axis=-1)
    if kappa is None or last is None:
        return u
    kap = np.unique(np.append(np.asarray(kappa, dtype=np.int64), last))
    legs = np.linalg.norm(np.diff(exp[kap], axis=0), axis=-1)
    remaining = np.concatenate([np.cumsum(legs[::-1])[::-1], [0.0]])  # path from kap[i] on
    return u + remaining[np.searchsorted(kap, k_next)]


def normalise(d: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """v = (hi - d) / (hi - lo), clipped to [0, 1]; all ones when the range is empty."""
    d = np.asarray(d, dtype=np.float64)
    if hi - lo <= 1e-12:
        return np.ones_like(d)
    return np.clip((hi - d) / (hi - lo), 0.0, 1.0)


def chain_subtasks(v: np.ndarray, subtask: np.ndarray, completion: np.ndarray) -> np.ndarray:
    """raw_t = sum of completion values of the subtasks before step t's subtask, plus v_t.

    ``completion[i]`` is the value the expert has at the end of subtask i. Crediting the
    expert's completion (rather than this rollout's last value in subtask i) keeps the
    value a function of the state: a recovery that lands on an expert state of a later
    subtask gets exactly the expert's value there.
    """
    offsets = np.concatenate([[0.0], np.cumsum(np.asarray(completion, dtype=np.float64))])
    return offsets[np.asarray(subtask)] + np.asarray(v, dtype=np.float64)


def rescale_from_start(raw: np.ndarray, total: float) -> np.ndarray:
    """progress = clip((raw - raw_0) / (total - raw_0), 0, 1): the start is exactly 0.

    ``total`` is the expert's final chained value, so the expert ends at exactly 1 and a
    trajectory that terminates early can never reach 1. States worse than the start
    clip to 0 (no progress).
    """
    raw = np.asarray(raw, dtype=np.float64)
    den = float(total - raw[0])
    if den <= 1e-12:
        return np.zeros_like(raw)
    out = np.clip((raw - raw[0]) / den, 0.0, 1.0)
    out[0] = 0.0
    return out


# ---------------------------------------------------------------- sequencing
def subtask_goal_distance(
    tracks: Tracks, sub: SubtaskLike, joint_span: float | None = None
) -> np.ndarray:
    """y for every step of ``tracks`` under one subtask's points and beta.

    With ``joint_span`` (m) and a subtask that names a ``joint`` point (an articulated
    object's fraction of the way to its goal, in the point's x), the goal term is
    ``(1 - fraction) * joint_span`` instead of the object-goal distance: continuous and
    monotone in the joint, even for a knob whose centre never moves.
    """
    if len(sub.robot_points) != len(sub.object_points):
        raise ValueError(f"subtask on {sub.object!r}: robot_points and object_points differ")
    robot = np.stack([tracks.points[n] for n in sub.robot_points], axis=1)
    objc = np.stack([tracks.points[n] for n in sub.object_points], axis=1)
    joint = getattr(sub, "joint", None)
    if joint_span is not None and joint and sub.goal is not None:
        y_re = np.linalg.norm(robot - objc, axis=-1).sum(axis=-1)
        frac = np.clip(tracks.points[joint][:, 0], 0.0, 1.0)
        return (1.0 - sub.beta) * y_re + sub.beta * (1.0 - frac) * joint_span
    goal = tracks.points[sub.goal] if sub.goal is not None else None
    return goal_distance(robot, objc, tracks.points[sub.object], goal, sub.beta)


def _joint_span(expert: Tracks, sub: SubtaskLike, a: int) -> float | None:
    """The grip point's distance to its goal at the expert subtask's first step (m), at
    least `JOINT_SPAN_MIN`."""
    if not getattr(sub, "joint", None) or sub.goal is None:
        return None
    p = expert.points[sub.object_points[0]][a]
    return max(float(np.linalg.norm(p - expert.points[sub.goal][a])), JOINT_SPAN_MIN)


def _reach(
    tracks: Tracks, q: np.ndarray, sub_idx: np.ndarray, subtasks, bounds
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steps whose state already meets the end test of their subtask or a later one are
    valued past it: (q, subtask, done).

    A rollout step's q is where it branched off the expert, so on a random ending that
    happens to finish a subtask (a knob turned all the way, a drawer pulled open) q lags
    the state and the step would be valued in the earlier subtask, capped at its share
    (the "ends at exactly 0.50" videos). Such a step moves to the subtask after the last
    one whose test it meets, from that subtask's first expert step; meeting the last
    subtask's test is the task done (``done``: valued as the expert's end). The expert
    itself is unchanged: it meets each test first at the end of that subtask.
    """
    q, sub_idx = q.copy(), sub_idx.copy()
    done = np.zeros(len(q), dtype=bool)
    if not tracks.reached:
        return q, sub_idx, done
    n_sub = len(subtasks)
    hit = np.stack(
        [tracks.reached.get(s.end_signal, np.zeros(len(q), bool)) for s in subtasks], axis=1
    )
    for r in range(len(q)):
        met = np.flatnonzero(hit[r, int(sub_idx[r]) :])
        if not len(met):
            continue
        i = int(sub_idx[r]) + int(met[-1])
        if i == n_sub - 1:
            done[r] = True
            sub_idx[r], q[r] = i, max(int(q[r]), bounds[i][0])
        else:
            sub_idx[r], q[r] = i + 1, max(int(q[r]), bounds[i + 1][0])
    return q, sub_idx, done


LANDING_STEPS = 10  # control steps (0.5 s at 20 Hz) a released object may fall to its goal


def _undo(
    tracks: Tracks, q: np.ndarray, sub_idx: np.ndarray, subtasks, bounds
) -> tuple[np.ndarray, np.ndarray]:
    """Steps whose state undoes a finished subtask are valued in that subtask.

    Subtask i is undone at a step of a later subtask when its achievement no longer
    stands (`Tracks.kept`) and no subtask after it stands either (a can resting in its
    bin keeps the grasp subtask done although nothing holds it any more). Such a step
    gets subtask i's value of its state, measured against i's last expert step. A step
    from which a later subtask stands again within `LANDING_STEPS` (an object let go just
    above its goal, in the air for a few steps) is in flight to it, not undone: valued as
    undone, the cereal box falling into its bin read 0.00 for one frame between 0.98 and 1.
    """
    q, sub_idx = q.copy(), sub_idx.copy()
    if not tracks.kept:
        return q, sub_idx
    n_sub = len(subtasks)
    stand = np.stack(
        [tracks.kept.get(s.end_signal, np.ones(len(q), bool)) for s in subtasks], axis=1
    )
    for r in range(len(q)):
        k = int(sub_idx[r])
        for i in range(k):
            landing = stand[r : r + LANDING_STEPS + 1, i + 1 : n_sub].any()
            if not stand[r, i] and not stand[r, i + 1 : n_sub].any() and not landing:
                sub_idx[r], q[r] = i, bounds[i][1]
                break
    return q, sub_idx


def progress_from_tracks(
    tracks: Tracks,
    q: np.ndarray,
    expert_tracks: Tracks,
    subtasks: Sequence[SubtaskLike],
    bounds: Sequence[tuple[int, int]],
    *,
    chain_keypoints: bool = True,
    range_mode: Literal["expert", "union"] = "expert",
    min_prominence: float = KEYPOINT_PROMINENCE,
    goal_end: int | None = None,
    form: Literal["rover", "paper"] = "rover",
) -> np.ndarray:
    """Ground-truth progress in [0, 1] for each rollout step.

    Args:
        tracks: rollout point tracks (N steps).
        q: (N,) expert index of each rollout step (the branch point on deviation steps).
        expert_tracks: the expert's point tracks (T steps).
        subtasks: one spec per subtask, in order.
        bounds: inclusive expert (start, end) of each subtask.
        chain_keypoints: add the expert's remaining keypoint path to u (see
            `trajectory_distance`); False gives the paper's plain u.
        range_mode: "expert" normalises d by the expert subtask's min and max (rollout
            states worse than the expert's worst clip to 0); "union" also lets the
            rollout's own d raise the max.
        min_prominence: keypoint prominence threshold (fraction of y's range).
        goal_end: expert step at which the last subtask's goal is achieved; the expert
            steps after it (the hand retreating) are valued as done while the goal still
            stands. None: the last subtask runs to the expert's last step (the paper).
        form: "rover" (default) adds four departures from Sec. 4.2, each documented in
            docs/ground_truth.md: articulated goals measured by joint state, subtasks ending
            at their goal (`goal_end`), undone subtasks revalued (`Tracks.kept`), and
            steps whose state meets a later subtask's end test valued past it
            (`Tracks.reached`); "paper" uses the paper's formulas only.
    """
    q = np.asarray(q, dtype=np.int64)
    if len(subtasks) != len(bounds):
        raise ValueError(f"{len(subtasks)} subtask specs for {len(bounds)} subtask bounds")
    rover = form == "rover"
    bounds = [tuple(b) for b in bounds]
    after_goal = np.zeros(len(q), dtype=bool)
    if rover and goal_end is not None and bounds[-1][0] <= goal_end < bounds[-1][1]:
        after_goal = q > goal_end
        bounds[-1] = (bounds[-1][0], int(goal_end))
        q = np.minimum(q, goal_end)
    ends = np.asarray([b for _, b in bounds])
    sub_idx = np.minimum(np.searchsorted(ends, q, side="left"), len(ends) - 1)
    if rover:
        q, sub_idx, done = _reach(tracks, q, sub_idx, subtasks, bounds)
        q, sub_idx = _undo(tracks, q, sub_idx, subtasks, bounds)
        last_kept = tracks.kept.get(getattr(subtasks[-1], "end_signal", ""))
        if last_kept is not None:
            after_goal &= last_kept
        after_goal |= done & (sub_idx == len(bounds) - 1)
        after_goal &= sub_idx == len(bounds) - 1
    v = np.zeros(len(q))
    completion = np.zeros(len(bounds))
    for i, (spec, (a, b)) in enumerate(zip(subtasks, bounds, strict=True)):
        e_idx = np.arange(a, b + 1)
        span = _joint_span(expert_tracks, spec, a) if rover else None
        y_e = subtask_goal_distance(expert_tracks.take(e_idx), spec, span)
        kappa = a + keypoints(y_e, min_prominence)
        extra = {"kappa": kappa, "last": b} if chain_keypoints else {}
        u_e = trajectory_distance(
            expert_tracks.entities[e_idx],
            expert_tracks.entities,
            next_keypoint(e_idx, kappa, b),
            **extra,
        )
        d_e = y_e + u_e
        lo, hi = float(d_e.min()), float(d_e.max())
        mask = sub_idx == i
        if mask.any():
            r = np.flatnonzero(mask)
            sub_tracks = tracks.take(r)
            y_n = subtask_goal_distance(sub_tracks, spec, span)
            u_n = trajectory_distance(
                sub_tracks.entities,
                expert_tracks.entities,
                next_keypoint(q[r], kappa, b),
                **extra,
            )
            d_n = y_n + u_n
            if range_mode == "union":
                hi = max(hi, float(d_n.max()))
            v[r] = normalise(d_n, lo, hi)
        completion[i] = normalise(d_e[-1:], lo, hi)[0]
    v[after_goal] = completion[-1]
    raw = chain_subtasks(v, sub_idx, completion)
    return rescale_from_start(raw, float(completion.sum()))


def ground_truth_value(
    adapter: SimAdapter,
    states: np.ndarray,
    q: np.ndarray,
    expert_states: np.ndarray,
    subtasks: Sequence[SubtaskLike],
    bounds: Sequence[tuple[int, int]],
    *,
    expert_tracks: Tracks | None = None,
    chain_keypoints: bool = True,
    range_mode: Literal["expert", "union"] = "expert",
    min_prominence: float = KEYPOINT_PROMINENCE,
) -> np.ndarray:
    """Progress for a rollout measured in the simulator (sets each state once).

    Pass ``expert_tracks`` (from `point_tracks` on the expert states) when many rollouts
    share one expert demonstration, so the expert is measured only once. The keyword
    options are those of `progress_from_tracks`.
    """
    names = required_points(subtasks)
    if expert_tracks is None:
        expert_tracks = point_tracks(adapter, expert_states, names)
    tracks = point_tracks(adapter, states, names)
    return progress_from_tracks(
        tracks,
        q,
        expert_tracks,
        subtasks,
        bounds,
        chain_keypoints=chain_keypoints,
        range_mode=range_mode,
        min_prominence=min_prominence,
    )
