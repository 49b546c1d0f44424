"""Non-expert trajectories from expert demonstrations (paper Sec. 4.1).

A trajectory is planned first (`plan_trajectory`: pure, seeded, no simulator) and then
executed against a simulator (`execute_plan`). A plan is a flat list of segments:

* `ExpertSegment` shows expert states ``start..end``. By default the recorded states ARE
  the expert's states (set, not re-simulated): after a recovery teleports to
  ``s^E_{q+h}``, replaying expert actions would drift from the expert because MuJoCo
  states do not capture warm-start and controller internals, and the video should show
  the expert path. ``free=True`` replays the expert actions from the current state instead.
* `RandomSegment` executes ``w`` actions drawn uniformly from the (scaled) action space
  starting from the current state: a deviation branching at expert index ``q``.
* `InterpSegment` recovers: ``s_{q,w,z} = interp(s_{q,w}, s^E_{q+h}, z / n_interp)`` for
  ``z = 1 .. z_stop``. With a simulator that offers ``drive_robot`` (rover's `SimEnv`),
  only the robot's joints are interpolated and the rest is simulated, so free objects
  never teleport (the paper interpolates the whole state); `Rollout.recovery_gap` then
  says how far an object ends from the expert state the recovery hands over to. The state
  at ``z = n_interp`` equals ``s^E_{q+h}`` and is recorded
  by the `ExpertSegment` starting at ``q + h``; a nested deviation may cut the recovery
  short (``z_stop < n_interp``) and start its own recovery from where it ends.

Every recorded step carries (q, j, z): q the expert index where the current branch left
the expert, j the random steps taken since then (cumulative over nested deviations), z the
interpolation step of the current recovery; plus the nesting depth and its StateType.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from rover.episode import StateType
from rover.sim.adapter import SimAdapter
from rover.sim.levels import LevelSpec, level_schedule, plan_seed

Bounds = Sequence[tuple[int, int]]


@dataclass(frozen=True)
class ExpertSegment:
    """Expert states ``start..end`` inclusive."""

    start: int
    end: int
    free: bool = False


@dataclass(frozen=True)
class RandomSegment:
    """``w`` uniformly random actions branching from expert index ``q``."""

    q: int
    w: int
    scale: float = 1.0
    hold: int = 1
    depth: int = 0
    grip: float | None = None  # gripper command held throughout (None: random like the rest)
    drift: tuple[float, float, float] | None = None  # added to the x, y, z channels
    # the first `settle` of the w steps keep the gripper closed and move the hand by the
    # drift alone (no random part, no `grip`): a just-lifted object is set back down
    # before the fingers open; the drift then stops, so the open hand stays at it
    settle: int = 0


@dataclass(frozen=True)
class InterpSegment:
    """Recovery toward expert state ``target`` in ``n_interp`` steps, recorded up to ``z_stop``."""

    q: int
    target: int
    n_interp: int
    z_stop: int
    depth: int = 0


Segment = ExpertSegment | RandomSegment | InterpSegment


@dataclass(frozen=True)
class TrajectoryPlan:
    """What a video will do, before any simulation."""

    expert_len: int
    subtask_bounds: tuple[tuple[int, int], ...]
    segments: tuple[Segment, ...]
    level: int | None = None
    terminated: bool = False

    @property
    def num_steps(self) -> int:
        """Number of recorded steps `execute_plan` will produce."""
        n = 0
        for seg in self.segments:
            if isinstance(seg, ExpertSegment):
                n += seg.end - seg.start + 1
            elif isinstance(seg, RandomSegment):
                n += seg.w
            else:
                n += seg.z_stop
        return n


@dataclass
class Rollout:
    """An executed plan: one state per recorded step plus its provenance."""

    states: np.ndarray  # (N, S) flat simulator states
    q: np.ndarray  # (N,) expert index the step is anchored to
    j: np.ndarray  # (N,) random steps since leaving the expert
    z: np.ndarray  # (N,) interpolation step of the current recovery
    depth: np.ndarray  # (N,) nesting depth of the deviation (0 on expert steps)
    state_type: list[StateType]
    subtask: np.ndarray  # (N,) subtask index of q
    terminated: bool
    plan: TrajectoryPlan | None = field(default=None, repr=False)
    # m: the largest jump of a task object where a physical recovery hands over to the
    # recorded expert (0 when recoveries are plain interpolation or none happen)
    recovery_gap: float = 0.0

    def __len__(self) -> int:
        return int(self.states.shape[0])


def check_bounds(expert_len: int, bounds: Bounds) -> tuple[tuple[int, int], ...]:
    """Validate inclusive subtask bounds that tile ``0..expert_len-1`` in order."""
    out = tuple((int(a), int(b)) for a, b in bounds)
    if not out:
        raise ValueError("at least one subtask is needed")
    if out[0][0] != 0 or out[-1][1] != expert_len - 1:
        raise ValueError(f"subtask bounds {out} must cover 0..{expert_len - 1}")
    for (_, b0), (a1, _) in zip(out, out[1:], strict=False):
        if a1 != b0 + 1:
            raise ValueError(f"subtask bounds {out} must be contiguous")
    if any(b < a for a, b in out):
        raise ValueError(f"subtask bounds {out} contain an empty subtask")
    return out


def bounds_from_ends(ends: Sequence[int], expert_len: int) -> list[tuple[int, int]]:
    """Inclusive subtask bounds from the step at which each subtask's end signal holds.

    Subtask i runs from the step after subtask i-1 ended to the step its own end signal
    first holds; the last subtask absorbs the remaining steps (the expert's final hold).
    """
    bounds: list[tuple[int, int]] = []
    start = 0
    for i, e in enumerate(ends):
        end = expert_len - 1 if i == len(ends) - 1 else int(e)
        if end < start:
            raise ValueError(f"subtask ends {list(ends)} are not increasing")
        bounds.append((start, end))
        start = end + 1
    return bounds


def subtask_of(q: np.ndarray | int, bounds: Bounds) -> np.ndarray:
    """Subtask index of expert index (or indices) ``q``."""
    ends = np.asarray([b for _, b in bounds])
    return np.minimum(np.searchsorted(ends, np.asarray(q), side="left"), len(ends) - 1)


def _draw(rng: np.random.Generator, r: tuple[int, int]) -> int:
    return int(rng.integers(r[0], r[1] + 1))


def _drawf(rng: np.random.Generator, r: tuple[float, float]) -> float:
    return float(rng.uniform(r[0], r[1])) if r[1] > r[0] else float(r[0])


def plan_trajectory(
    expert_len: int,
    subtask_bounds: Bounds,
    level: LevelSpec,
    rng: np.random.Generator,
    cut: int | None = None,
    deviate_before: int | None = None,
) -> TrajectoryPlan:
    """Plan one non-expert trajectory of the given level; pure and deterministic for ``rng``.

    The trajectory follows the expert, branching at sorted random points q into
    recovered deviations (random actions, then interpolation to ``s^E_{q+h}``), some with
    a nested deviation inside the deviation or inside the recovery (branch points that
    an earlier recovery already jumped past are dropped). Terminating levels end with an
    unrecovered deviation starting inside ``level.terminate_subtask``; completing levels
    end with the expert's final state.

    Args:
        expert_len: number of expert states T.
        subtask_bounds: inclusive (start, end) expert indices of each subtask, tiling 0..T-1.
        level: the level's knobs.
        rng: the video's Generator (see `rover.sim.levels.plan_seed`).
        cut: expert step at which a terminating level leaves the expert for good (from
            `rover.sim.cuts`); None draws it from ``terminate_subtask``/``terminate_at``.
        deviate_before: recovered deviations branch before this expert step (None: any
            step before the cut). A level's window starts where its last component is
            achieved; random actions after that, next to the object, can achieve the
            next one (push the door ajar) before the video even leaves the expert.
    """
    bounds = check_bounds(expert_len, subtask_bounds)
    last = expert_len - 1
    if level.terminate_subtask is not None and cut is not None:
        q_end = min(max(int(cut), 0), last)
    elif level.terminate_subtask is not None:
        k = min(max(level.terminate_subtask, 0), len(bounds) - 1)
        a, b = bounds[k]
        q_end = a + int(round(_drawf(rng, level.terminate_at) * (b - a)))
    else:
        q_end = last
    n_dev = _draw(rng, level.deviations)
    # branch points leave room for the recovery horizon before the end point
    room = q_end - 1 if deviate_before is None else min(q_end, int(deviate_before)) - 1
    qs = sorted(rng.choice(room, size=min(n_dev, room), replace=False).tolist()) if room > 0 else []

    segments: list[Segment] = []
    cursor = 0
    for q in qs:
        if q < cursor:  # an earlier recovery already jumped past this branch point
            continue
        segments.append(ExpertSegment(cursor, q))
        segments.append(_random(rng, level, q, 0))
        target = min(q + _draw(rng, level.h), q_end)
        n = _draw(rng, level.n_interp)
        nested = rng.random() < level.nested_prob
        if nested and rng.random() < 0.5:
            # a deviation inside the deviation: a second burst with its own magnitude
            segments.append(_random(rng, level, q, 1))
            segments.append(InterpSegment(q, target, n, n - 1, 1))
        elif nested and n > 1 and target < q_end:
            # a deviation inside the recovery, which then recovers further downstream
            z0 = _draw(rng, (1, n - 1))
            segments.append(InterpSegment(q, target, n, z0, 0))
            segments.append(_random(rng, level, q, 1))
            target = min(target + _draw(rng, level.h), q_end)
            n = _draw(rng, level.n_interp)
            segments.append(InterpSegment(q, target, n, n - 1, 1))
        else:
            segments.append(InterpSegment(q, target, n, n - 1, 0))
        cursor = target
    segments.append(ExpertSegment(cursor, max(cursor, q_end)))
    terminated = level.terminate_subtask is not None
    if terminated:
        w = _draw(rng, level.terminal_w)
        segments.append(
            RandomSegment(
                q_end, w, _drawf(rng, level.scale), min(_draw(rng, level.hold), w), depth=0
            )
        )
    return TrajectoryPlan(
        expert_len=expert_len,
        subtask_bounds=bounds,
        segments=tuple(segments),
        level=level.level,
        terminated=terminated,
    )


def _random(rng: np.random.Generator, level: LevelSpec, q: int, depth: int) -> RandomSegment:
    w = _draw(rng, level.w)
    return RandomSegment(q, w, _drawf(rng, level.scale), min(_draw(rng, level.hold), w), depth)


def plans_for_levels(
    expert_len: int,
    subtask_bounds: Bounds,
    levels: Sequence[LevelSpec],
    per_level: int,
    seed: int,
    task: str,
) -> list[TrajectoryPlan]:
    """``per_level`` diverse plans for every level, deterministic for ``(seed, task)``."""
    return [
        plan_trajectory(expert_len, subtask_bounds, spec, plan_seed(seed, task, index))
        for index, spec in level_schedule(levels, per_level)
    ]


def random_action(
    rng: np.random.Generator, low: np.ndarray, high: np.ndarray, scale: float
) -> np.ndarray:
    """An action uniform in the action box shrunk by ``scale`` around its centre."""
    low = np.asarray(low, dtype=np.float64)
    high = np.asarray(high, dtype=np.float64)
    mid, half = (low + high) / 2.0, (high - low) / 2.0
    return mid + scale * half * rng.uniform(-1.0, 1.0, size=low.shape)


def execute_plan(
    adapter: SimAdapter,
    expert_states: np.ndarray,
    expert_actions: np.ndarray,
    plan: TrajectoryPlan,
    rng: np.random.Generator,
) -> Rollout:
    """Run a plan in the simulator and record one state per step.

    Args:
        adapter: the simulator; its state is changed.
        expert_states: (T, S) expert flat states, T == plan.expert_len.
        expert_actions: (T-1, A) or (T, A); action t takes state t to t+1 (used only by
            ``free`` expert segments).
        plan: from `plan_trajectory`.
        rng: draws the random actions (keep it separate from the planning Generator
            if the plan must be reproducible on its own).
    """
    expert_states = np.asarray(expert_states, dtype=np.float64)
    if expert_states.shape[0] != plan.expert_len:
        raise ValueError(f"{expert_states.shape[0]} expert states for a plan of {plan.expert_len}")
    states: list[np.ndarray] = []
    idx: list[tuple[int, int, int, int]] = []
    types: list[StateType] = []
    j_total = 0
    mismatch = 0.0

    def record(s: np.ndarray, q: int, j: int, z: int, d: int, t: StateType) -> None:
        states.append(np.array(s, dtype=np.float64, copy=True))
        idx.append((q, j, z, d))
        types.append(t)

    for seg in plan.segments:
        if isinstance(seg, ExpertSegment):
            j_total = 0
            if seg.free:
                # start from the expert state (a finished recovery lands exactly on it)
                record(expert_states[seg.start], seg.start, 0, 0, 0, StateType.expert)
                adapter.set_state(expert_states[seg.start])
                for t in range(seg.start, seg.end):
                    adapter.step(np.asarray(expert_actions[t]))
                    record(adapter.get_state(), t + 1, 0, 0, 0, StateType.expert)
            else:
                for t in range(seg.start, seg.end + 1):
                    record(expert_states[t], t, 0, 0, 0, StateType.expert)
        elif isinstance(seg, RandomSegment):
            adapter.set_state(states[-1] if states else expert_states[seg.q])
            action = None
            for i in range(seg.w):
                if i < seg.settle:
                    action = random_action(rng, adapter.action_low, adapter.action_high, 0.0)
                    action[-1] = 1.0
                    if seg.drift is not None:
                        action[:3] = np.clip(action[:3] + np.asarray(seg.drift), -1.0, 1.0)
                elif i == seg.settle > 0 or action is None or (i - seg.settle) % seg.hold == 0:
                    action = random_action(rng, adapter.action_low, adapter.action_high, seg.scale)
                    if seg.grip is not None:  # the last channel is the gripper's
                        action[-1] = seg.grip
                    if seg.drift is not None and not seg.settle:  # the first three move the hand
                        action[:3] = np.clip(action[:3] + np.asarray(seg.drift), -1.0, 1.0)
                adapter.step(action)
                j_total += 1
                record(adapter.get_state(), seg.q, j_total, 0, seg.depth, StateType.non_expert)
        else:
            start = states[-1]
            goal = expert_states[seg.target]
            physical = hasattr(adapter, "drive_robot")
            if physical:
                adapter.set_state(start)
            for z in range(1, seg.z_stop + 1):
                if physical:  # robot interpolated, the rest simulated (no teleports)
                    adapter.drive_robot(start, goal, (z - 1) / seg.n_interp, z / seg.n_interp)
                    s = adapter.get_state()
                else:
                    s = adapter.interpolate(start, goal, z / seg.n_interp)
                record(s, seg.q, j_total, z, seg.depth, StateType.interpolating)
            if physical:
                mismatch = max(mismatch, _object_gap(adapter, adapter.get_state(), goal))
    arr = np.stack(states)
    ij = np.asarray(idx, dtype=np.int64)
    return Rollout(
        states=arr,
        q=ij[:, 0],
        j=ij[:, 1],
        z=ij[:, 2],
        depth=ij[:, 3],
        state_type=types,
        subtask=subtask_of(ij[:, 0], plan.subtask_bounds),
        terminated=plan.terminated,
        plan=plan,
        recovery_gap=mismatch,
    )


def _object_gap(adapter: SimAdapter, state: np.ndarray, expert: np.ndarray) -> float:
    """How far (m) any task object is from where the expert state has it: the jump the
    video would show when a physical recovery hands over to the recorded expert."""
    adapter.set_state(state)
    here = np.asarray(adapter.entity_positions())[1:]
    adapter.set_state(expert)
    there = np.asarray(adapter.entity_positions())[1:]
    adapter.set_state(state)
    return float(np.linalg.norm(here - there, axis=-1).max()) if len(here) else 0.0
