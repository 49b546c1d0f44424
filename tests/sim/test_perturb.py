"""Non-expert trajectories (Sec. 4.1) on a pure-numpy point-mass simulator, plus values."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rover.episode import StateType
from rover.sim.adapter import SimAdapter
from rover.sim.levels import LevelSpec, default_levels, plan_seed
from rover.sim.perturb import (
    ExpertSegment,
    InterpSegment,
    RandomSegment,
    TrajectoryPlan,
    bounds_from_ends,
    execute_plan,
    plan_trajectory,
    plans_for_levels,
    subtask_of,
)
from rover.sim.value import ground_truth_value, point_tracks, required_points

GOAL = np.array([0.3, 0.4, 0.0])
CUBE0 = np.array([0.3, 0.0, 0.0])
SPEED = 0.02  # metres per unit action per step


class PointMass:
    """A gripper point that carries a cube when closed near it.

    State ``[time, gripper xyz, cube xyz, gripper vel xyz, cube vel xyz]`` mimics
    robosuite's ``[time, qpos, qvel]`` layout; actions are ``(dx, dy, dz, grip)``.
    """

    action_low = -np.ones(4)
    action_high = np.ones(4)

    def __init__(self) -> None:
        self.s = np.zeros(13)
        self.s[1:4] = [0.0, 0.0, 0.2]
        self.s[4:7] = CUBE0
        self.steps = 0
        self.actions: list[np.ndarray] = []

    def get_state(self) -> np.ndarray:
        return self.s.copy()

    def set_state(self, state: np.ndarray) -> None:
        self.s = np.asarray(state, dtype=np.float64).copy()

    def step(self, action: np.ndarray) -> None:
        a = np.clip(action, -1, 1)
        self.actions.append(np.asarray(action).copy())
        self.steps += 1
        p, o = self.s[1:4].copy(), self.s[4:7].copy()
        new_p = p + SPEED * a[:3]
        new_o = new_p.copy() if a[3] > 0 and np.linalg.norm(p - o) < 0.05 else o
        self.s[0] += 0.05
        self.s[1:4], self.s[4:7] = new_p, new_o
        self.s[7:10], self.s[10:13] = (new_p - p) / 0.05, (new_o - o) / 0.05

    def interpolate(self, a: np.ndarray, b: np.ndarray, alpha: float) -> np.ndarray:
        return (1 - alpha) * np.asarray(a) + alpha * np.asarray(b)

    def entity_positions(self) -> np.ndarray:
        return np.stack([self.s[1:4], self.s[4:7]])

    def point(self, name: str) -> np.ndarray:
        p = self.s[1:4]
        table = {
            "eef": p,
            "left_finger": p + [0, 0.01, 0],
            "right_finger": p - [0, 0.01, 0],
            "cube": self.s[4:7],
            "goal:bin": GOAL,
        }
        return np.array(table[name], dtype=np.float64)

    def success(self) -> bool:
        return bool(np.linalg.norm(self.s[4:7] - GOAL) < 0.03)


SUBTASKS = [
    SimpleNamespace(
        object="cube",
        robot_points=["left_finger", "right_finger"],
        object_points=["cube", "cube"],
        goal=None,
        beta=0.0,
    ),
    SimpleNamespace(
        object="cube",
        robot_points=["left_finger", "right_finger"],
        object_points=["cube", "cube"],
        goal="goal:bin",
        beta=0.8,
    ),
]


def expert_demo(sim: PointMass) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """Scripted expert: reach the cube open, then carry it closed to the goal."""
    states, actions = [sim.get_state()], []
    grasp_end = None
    for _ in range(200):
        p, o = sim.s[1:4], sim.s[4:7]
        carrying = np.linalg.norm(p - o) < 0.05
        target = GOAL if carrying else o
        a = np.append(np.clip((target - p) / SPEED, -1, 1), 1.0 if carrying else -1.0)
        if carrying and grasp_end is None:
            grasp_end = len(states) - 1
        if carrying and np.linalg.norm(o - GOAL) < 1e-9:
            break
        sim.step(a)
        actions.append(a)
        states.append(sim.get_state())
    assert sim.success() and grasp_end is not None
    return np.stack(states), np.stack(actions), [(0, grasp_end), (grasp_end + 1, len(states) - 1)]


@pytest.fixture(scope="module")
def demo():
    return expert_demo(PointMass())


def test_point_mass_implements_the_protocol():
    assert isinstance(PointMass(), SimAdapter)


# ------------------------------------------------------------------ planning
def test_plan_is_deterministic_for_a_seed_and_diverse_across_seeds():
    level = LevelSpec(level=3, deviations=(1, 3), nested_prob=0.5)
    bounds = [(0, 39), (40, 99)]
    plans = [plan_trajectory(100, bounds, level, np.random.default_rng(s)) for s in range(12)]
    again = [plan_trajectory(100, bounds, level, np.random.default_rng(s)) for s in range(12)]
    assert plans == again
    assert len({p.segments for p in plans}) >= 10
    branch_points = {seg.q for p in plans for seg in p.segments if isinstance(seg, RandomSegment)}
    assert len(branch_points) >= 10


def test_plan_shapes_for_terminating_and_completing_levels():
    bounds = [(0, 39), (40, 99)]
    stop = LevelSpec(level=2, terminate_subtask=1, terminate_at=(0.5, 0.5), deviations=(2, 2))
    plan = plan_trajectory(100, bounds, stop, np.random.default_rng(0))
    assert plan.terminated
    assert plan.segments[0] == ExpertSegment(0, plan.segments[0].end)
    assert isinstance(plan.segments[-1], RandomSegment)
    assert plan.segments[-1].q == 40 + round(0.5 * 59)
    finish = LevelSpec(level=5, deviations=(3, 3), nested_prob=1.0)
    plan = plan_trajectory(100, bounds, finish, np.random.default_rng(1))
    assert not plan.terminated
    assert plan.segments[-1].end == 99
    assert any(isinstance(s, RandomSegment) and s.depth == 1 for s in plan.segments)


def test_plan_nests_deviations_in_deviations_and_in_recoveries():
    level = LevelSpec(level=5, deviations=(2, 2), nested_prob=1.0, n_interp=(3, 6))
    kinds = set()
    for seed in range(20):
        segs = plan_trajectory(200, [(0, 199)], level, np.random.default_rng(seed)).segments
        for prev, seg in zip(segs, segs[1:], strict=False):
            if isinstance(seg, RandomSegment) and seg.depth == 1:
                kinds.add(type(prev).__name__)
    assert kinds == {"RandomSegment", "InterpSegment"}


def test_plan_rejects_bounds_that_do_not_tile():
    level = LevelSpec(level=1)
    with pytest.raises(ValueError, match="cover"):
        plan_trajectory(100, [(0, 50)], level, np.random.default_rng(0))
    with pytest.raises(ValueError, match="contiguous"):
        plan_trajectory(100, [(0, 40), (42, 99)], level, np.random.default_rng(0))


def test_plans_for_levels_counts_and_determinism():
    levels = default_levels([["Approach the cube"], ["Approach the goal"]])
    assert [lv.level for lv in levels] == [1, 2, 3, 4, 5]
    plans = plans_for_levels(100, [(0, 39), (40, 99)], levels, per_level=3, seed=7, task="T")
    assert [p.level for p in plans] == [1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5]
    same = plans_for_levels(100, [(0, 39), (40, 99)], levels, per_level=3, seed=7, task="T")
    assert plans == same
    other = plans_for_levels(100, [(0, 39), (40, 99)], levels, per_level=3, seed=8, task="T")
    assert plans != other


def test_bounds_from_ends():
    assert bounds_from_ends([27, 35], 54) == [(0, 27), (28, 53)]  # last absorbs the hold
    assert bounds_from_ends([10], 20) == [(0, 19)]
    with pytest.raises(ValueError, match="increasing"):
        bounds_from_ends([10, 5, 30], 40)


def test_subtask_of():
    np.testing.assert_array_equal(
        subtask_of(np.array([0, 39, 40, 99]), [(0, 39), (40, 99)]), [0, 0, 1, 1]
    )


# ----------------------------------------------------------------- execution
def _plan(segments, terminated=False, n=20) -> TrajectoryPlan:
    return TrajectoryPlan(n, ((0, 9), (10, n - 1)), tuple(segments), 1, terminated)


def test_execute_indices_and_state_types(demo):
    states, actions, _ = demo
    plan = _plan(
        [
            ExpertSegment(0, 3),
            RandomSegment(3, w=2, scale=1.0),
            InterpSegment(3, target=6, n_interp=3, z_stop=2),
            ExpertSegment(6, 12),
        ]
    )
    sim = PointMass()
    r = execute_plan(sim, states[:20], actions[:19], plan, np.random.default_rng(0))
    assert len(r) == plan.num_steps == 4 + 2 + 2 + 7
    np.testing.assert_array_equal(r.q, [0, 1, 2, 3, 3, 3, 3, 3, 6, 7, 8, 9, 10, 11, 12])
    np.testing.assert_array_equal(r.j, [0, 0, 0, 0, 1, 2, 2, 2] + [0] * 7)
    np.testing.assert_array_equal(r.z, [0, 0, 0, 0, 0, 0, 1, 2] + [0] * 7)
    e, n, i = StateType.expert, StateType.non_expert, StateType.interpolating
    assert r.state_type == [e] * 4 + [n, n, i, i] + [e] * 7
    np.testing.assert_array_equal(r.subtask, [0] * 12 + [1] * 3)
    # expert segments record the expert's states themselves
    np.testing.assert_array_equal(r.states[:4], states[:4])
    np.testing.assert_array_equal(r.states[8:], states[6:13])
    # the deviation starts from s_{q,0} = expert state 3 and moves away from it
    assert not np.allclose(r.states[5], states[5])
    # recovery: alpha_z = z / n_interp from the last deviated state toward s^E_{q+h}
    np.testing.assert_allclose(r.states[6], (2 / 3) * r.states[5] + (1 / 3) * states[6])
    np.testing.assert_allclose(r.states[7], (1 / 3) * r.states[5] + (2 / 3) * states[6])
    assert sim.steps == 2 and not r.terminated


def test_execute_nested_deviation_inside_recovery(demo):
    states, actions, _ = demo
    plan = _plan(
        [
            ExpertSegment(0, 2),
            RandomSegment(2, w=2),
            InterpSegment(2, target=5, n_interp=4, z_stop=1),
            RandomSegment(2, w=1, depth=1),
            InterpSegment(2, target=7, n_interp=2, z_stop=1, depth=1),
            ExpertSegment(7, 9),
        ]
    )
    r = execute_plan(PointMass(), states[:20], actions[:19], plan, np.random.default_rng(1))
    np.testing.assert_array_equal(r.q, [0, 1, 2, 2, 2, 2, 2, 2, 7, 8, 9])
    np.testing.assert_array_equal(r.j, [0, 0, 0, 1, 2, 2, 3, 3, 0, 0, 0])
    np.testing.assert_array_equal(r.z, [0, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0])
    np.testing.assert_array_equal(r.depth, [0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0])
    # the nested deviation branches from the interpolated state, not from the expert
    assert np.linalg.norm(r.states[6][1:4] - r.states[5][1:4]) <= SPEED * np.sqrt(3) + 1e-12


def test_execute_random_actions_scaled_and_held(demo):
    states, actions, _ = demo
    plan = _plan([ExpertSegment(0, 1), RandomSegment(1, w=6, scale=0.25, hold=3)], True)
    sim = PointMass()
    r = execute_plan(sim, states[:20], actions[:19], plan, np.random.default_rng(2))
    acts = np.stack(sim.actions)
    assert np.all(np.abs(acts) <= 0.25)
    np.testing.assert_array_equal(acts[0], acts[2])  # held for 3 steps
    assert not np.allclose(acts[2], acts[3])  # then redrawn
    assert r.terminated and r.state_type[-1] == StateType.non_expert


def test_execute_free_expert_replay(demo):
    states, actions, _ = demo
    plan = _plan([ExpertSegment(0, 10, free=True)])
    sim = PointMass()
    r = execute_plan(sim, states[:20], actions[:19], plan, np.random.default_rng(0))
    assert sim.steps == 10
    np.testing.assert_allclose(r.states, states[:11])  # the point mass is deterministic


def test_execute_is_deterministic(demo):
    states, actions, bounds = demo
    level = LevelSpec(level=2, deviations=(2, 3), nested_prob=0.5)
    plan = plan_trajectory(len(states), bounds, level, plan_seed(0, "T", 1))
    a = execute_plan(PointMass(), states, actions, plan, np.random.default_rng(5))
    b = execute_plan(PointMass(), states, actions, plan, np.random.default_rng(5))
    np.testing.assert_array_equal(a.states, b.states)
    assert len(a) == plan.num_steps


# ------------------------------------------------------- values end to end
def _values(sim, states, demo, q):
    exp_states, _, bounds = demo
    return ground_truth_value(sim, states, q, exp_states, SUBTASKS, bounds)


def test_value_expert_rollout_goes_from_0_to_1(demo):
    states, actions, bounds = demo
    v = _values(PointMass(), states, demo, np.arange(len(states)))
    assert v[0] == 0.0 and v[-1] == pytest.approx(1.0)
    assert np.all(np.diff(v) >= -1e-9)
    assert v[bounds[0][1]] == pytest.approx(0.5, abs=0.05)  # grasp done: about half way


def test_value_levels_order_on_point_mass(demo):
    states, actions, bounds = demo
    levels = default_levels([["Approach the cube"], ["Approach the goal"]])
    sim = PointMass()
    finals: dict[int, list[float]] = {}
    for k, plan in enumerate(plans_for_levels(len(states), bounds, levels, 4, seed=3, task="pm")):
        r = execute_plan(sim, states, actions, plan, np.random.default_rng(k))
        v = _values(sim, r.states, demo, r.q)
        assert v[0] == 0.0 and np.all((v >= 0) & (v <= 1))
        finals.setdefault(plan.level, []).append(float(v[-1]))
    means = [np.mean(finals[lv]) for lv in sorted(finals)]
    assert means[0] < 0.2  # random from (nearly) the start stays low
    assert min(finals[5]) == pytest.approx(1.0)  # completing level ends on the expert's end
    assert all(b >= a - 0.05 for a, b in zip(means, means[1:], strict=False))


def test_point_tracks_restores_state(demo):
    states, _, _ = demo
    sim = PointMass()
    sim.set_state(states[3])
    tr = point_tracks(sim, states[:5], required_points(SUBTASKS))
    np.testing.assert_array_equal(sim.get_state(), states[3])
    assert tr.entities.shape == (5, 2, 3)
    np.testing.assert_allclose(tr.points["cube"][0], CUBE0)


@pytest.mark.parametrize(
    "expert_len, bounds", [(1, [(0, 0)]), (3, [(0, 0), (1, 2)]), (40, [(0, 9), (10, 29), (30, 39)])]
)
def test_any_plan_executes_consistently(expert_len, bounds):
    """Planned lengths match, q never decreases, starts on the expert, completes on it."""
    states = np.tile(PointMass().get_state(), (expert_len, 1))
    states[:, 1] += 0.01 * np.arange(expert_len)
    actions = np.zeros((expert_len, 4))
    milestones = [["a"]] * len(bounds)
    wild = LevelSpec(level=99, deviations=(4, 8), nested_prob=1.0, h=(1, 3), n_interp=(1, 4))
    for level in [*default_levels(milestones), wild]:
        for seed in range(3):
            plan = plan_trajectory(expert_len, bounds, level, np.random.default_rng(seed))
            r = execute_plan(PointMass(), states, actions, plan, np.random.default_rng(seed))
            assert len(r) == plan.num_steps
            assert r.q[0] == 0 and r.state_type[0] == StateType.expert
            assert np.all(np.diff(r.q) >= 0) and r.q.max() <= expert_len - 1
            if not plan.terminated:
                assert r.q[-1] == expert_len - 1 and r.state_type[-1] == StateType.expert
