"""Ground-truth value formulas (paper Sec. 4.2) on small hand-computed cases."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rover.sim.value import (
    Tracks,
    chain_subtasks,
    goal_distance,
    keypoints,
    next_keypoint,
    normalise,
    progress_from_tracks,
    required_points,
    rescale_from_start,
    trajectory_distance,
)


def _pts(rows):
    return np.asarray(rows, dtype=np.float64)


def test_goal_distance_beta_0_is_contact_sum():
    # two contact pairs, 3 m and 4 m apart
    robot = _pts([[0, 0, 0], [0, 0, 0]])[None]
    objc = _pts([[3, 0, 0], [0, 4, 0]])[None]
    y = goal_distance(robot, objc, _pts([0, 0, 0])[None], _pts([0, 0, 10])[None], beta=0.0)
    np.testing.assert_allclose(y, [7.0])


def test_goal_distance_beta_1_is_object_to_goal():
    robot = _pts([[0, 0, 0]])[None]
    objc = _pts([[3, 0, 0]])[None]
    y = goal_distance(robot, objc, _pts([1, 1, 0])[None], _pts([4, 5, 0])[None], beta=1.0)
    np.testing.assert_allclose(y, [5.0])  # 3-4-5 triangle


def test_goal_distance_beta_half_mixes_and_no_goal_ignores_beta():
    robot = _pts([[0, 0, 0]])[None]
    objc = _pts([[2, 0, 0]])[None]
    obj, goal = _pts([0, 0, 0])[None], _pts([0, 6, 0])[None]
    np.testing.assert_allclose(goal_distance(robot, objc, obj, goal, 0.5), [4.0])
    np.testing.assert_allclose(goal_distance(robot, objc, obj, None, 0.5), [2.0])


def test_goal_distance_per_step():
    robot = np.zeros((3, 1, 3))
    objc = np.array([[[1, 0, 0]], [[2, 0, 0]], [[0, 0, 0]]], dtype=float)
    np.testing.assert_allclose(goal_distance(robot, objc, None, None, 0.0), [1, 2, 0])


def test_keypoints_of_hand_made_curve():
    # maxima at 2 (prominent) and 6 (prominent); the wiggle at 9 is below 10% of the range
    y = np.array([5, 6, 8, 4, 2, 3, 7, 1, 1.0, 1.2, 1.1, 0])
    np.testing.assert_array_equal(keypoints(y), [2, 6])
    np.testing.assert_array_equal(keypoints(y, min_prominence=0.0), [2, 6, 9])


def test_keypoints_plateau_and_monotone():
    assert keypoints(np.array([3.0, 2, 1, 0])).size == 0  # endpoints never count
    np.testing.assert_array_equal(keypoints(np.array([0, 2, 2, 2, 0.0])), [1])
    assert keypoints(np.array([0, 2, 2, 3.0])).size == 0  # plateau rising to the end


def test_next_keypoint_strictly_after_q_with_end_fallback():
    kappa = np.array([3, 7])
    q = np.array([0, 3, 4, 7, 8, 10])
    np.testing.assert_array_equal(next_keypoint(q, kappa, last=10), [3, 7, 7, 10, 10, 10])


def test_trajectory_distance_to_known_next_keypoint():
    # one entity (B = 1); expert passes keypoint 1 at (0, 0, 1) and ends at (0, 0, 0)
    expert = _pts([[[0, 0, 2]], [[0, 0, 1]], [[0, 0, 0]]])
    rollout = _pts([[[3, 0, 1]], [[0, 4, 0]]])
    k_next = np.array([1, 2])
    np.testing.assert_allclose(trajectory_distance(rollout, expert, k_next), [3.0, 4.0])
    # chained: add the expert's remaining path after k_next (1 -> 2 is 1 m)
    u = trajectory_distance(rollout, expert, k_next, kappa=np.array([1]), last=2)
    np.testing.assert_allclose(u, [4.0, 4.0])


def test_trajectory_distance_flattens_all_entities():
    expert = np.zeros((2, 2, 3))
    rollout = np.array([[[3, 0, 0], [0, 4, 0]]], dtype=float)  # two entities, 3 and 4 off
    np.testing.assert_allclose(trajectory_distance(rollout, expert, np.array([1])), [5.0])


def test_normalise_inverts_rescales_and_clips():
    np.testing.assert_allclose(normalise(np.array([10, 5, 0, 12, -1]), 0, 10), [0, 0.5, 1, 0, 1])
    np.testing.assert_allclose(normalise(np.array([3.0, 3.0]), 3.0, 3.0), [1, 1])


def test_chain_two_subtasks_then_rescale():
    v = np.array([0.0, 0.5, 1.0, 0.2, 0.6, 1.0])
    sub = np.array([0, 0, 0, 1, 1, 1])
    raw = chain_subtasks(v, sub, completion=np.array([1.0, 1.0]))
    np.testing.assert_allclose(raw, [0, 0.5, 1, 1.2, 1.6, 2.0])
    np.testing.assert_allclose(rescale_from_start(raw, 2.0), [0, 0.25, 0.5, 0.6, 0.8, 1.0])


def test_rescale_from_start_zero_start_clip_and_short_total():
    raw = np.array([0.4, 0.2, 0.7, 1.0])
    out = rescale_from_start(raw, total=1.0)
    assert out[0] == 0.0
    np.testing.assert_allclose(out, [0, 0, 0.5, 1.0])
    # terminated early: the expert's total is 2, so reaching 1 is only half way
    np.testing.assert_allclose(rescale_from_start(np.array([0.0, 1.0]), 2.0), [0, 0.5])


def _line_tracks(eef: np.ndarray, cube: np.ndarray, goal: np.ndarray) -> Tracks:
    return Tracks(
        points={"eef": eef, "cube": cube, "goal:bin": goal},
        entities=np.stack([eef, cube], axis=1),
    )


SUBTASKS = [
    SimpleNamespace(object="cube", robot_points=["eef"], object_points=["cube"], goal=None, beta=0),
    SimpleNamespace(
        object="cube", robot_points=["eef"], object_points=["cube"], goal="goal:bin", beta=0.8
    ),
]


def _expert_line(n: int = 11) -> Tracks:
    """eef moves from x=0 to the cube at x=1 (steps 0..5), then carries it to x=2."""
    eef = np.zeros((n, 3))
    eef[:, 0] = np.concatenate([np.linspace(0, 1, 6), np.linspace(1.2, 2, n - 6)])
    cube = np.zeros((n, 3))
    cube[:, 0] = np.maximum(eef[:, 0], 1.0)
    goal = np.tile([2.0, 0, 0], (n, 1))
    return _line_tracks(eef, cube, goal)


def test_required_points_in_first_use_order():
    assert required_points(SUBTASKS) == ["eef", "cube", "goal:bin"]


def test_expert_progress_starts_at_0_ends_at_1_and_rises():
    expert = _expert_line()
    bounds = [(0, 5), (6, 10)]
    p = progress_from_tracks(expert, np.arange(11), expert, SUBTASKS, bounds)
    assert p[0] == 0.0
    assert p[-1] == pytest.approx(1.0)
    assert np.all(np.diff(p) >= -1e-9)
    assert p[5] == pytest.approx(0.5)  # subtask 1 done = half of the task


def test_terminated_rollout_stays_in_its_subtask_share():
    expert = _expert_line()
    bounds = [(0, 5), (6, 10)]
    # follows the expert to step 3, then wanders away in subtask 0 and stops there
    idx = np.array([0, 1, 2, 3, 3, 3])
    rollout = expert.take(idx)
    rollout.points["eef"] = rollout.points["eef"].copy()
    rollout.points["eef"][4:, 1] = [0.5, 3.0]
    rollout.entities = np.stack([rollout.points["eef"], rollout.points["cube"]], axis=1)
    p = progress_from_tracks(rollout, idx, expert, SUBTASKS, bounds)
    assert p[0] == 0.0
    assert p.max() <= 0.5
    assert p[-1] < p[3]  # moving away loses value
    assert p[-1] == 0.0  # far worse than the expert's worst: clipped to no progress


def test_rollout_jumping_into_next_subtask_gets_expert_value_there():
    expert = _expert_line()
    bounds = [(0, 5), (6, 10)]
    full = progress_from_tracks(expert, np.arange(11), expert, SUBTASKS, bounds)
    idx = np.array([0, 1, 8, 9, 10])  # a recovery landing on expert state 8
    p = progress_from_tracks(expert.take(idx), idx, expert, SUBTASKS, bounds)
    np.testing.assert_allclose(p, full[idx])


def test_chained_u_keeps_expert_monotone_over_a_keypoint():
    """Lift an object over an obstacle: y peaks at the top (a keypoint)."""
    up = [(0, 0, z) for z in np.linspace(0, 1, 6)]
    over = [(x, 0, 1) for x in np.linspace(0.4, 2, 5)]
    down = [(2, 0, z) for z in np.linspace(0.8, 0, 5)]
    obj = np.array(up + over + down, dtype=float)
    n = len(obj)
    tracks = Tracks(
        points={"eef": obj, "box": obj, "goal:g": np.tile([2.0, 0, 0], (n, 1))},
        entities=np.stack([obj, obj], axis=1),
    )
    sub = [
        SimpleNamespace(
            object="box", robot_points=["eef"], object_points=["box"], goal="goal:g", beta=1.0
        )
    ]
    y = goal_distance(obj[:, None], obj[:, None], obj, tracks.points["goal:g"], 1.0)
    np.testing.assert_array_equal(keypoints(y), [5])  # the top of the lift
    q = np.arange(n)
    chained = progress_from_tracks(tracks, q, tracks, sub, [(0, n - 1)])
    plain = progress_from_tracks(tracks, q, tracks, sub, [(0, n - 1)], chain_keypoints=False)
    assert chained[-1] == pytest.approx(1.0) and plain[-1] == pytest.approx(1.0)
    assert np.diff(chained).min() >= -1e-9
    assert np.diff(plain).min() < -0.1  # the paper's u jumps when q passes the keypoint
