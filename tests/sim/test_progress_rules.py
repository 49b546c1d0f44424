"""rover's departures from Sec. 4.2 in the value: undo, end at the goal, joint goals."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rover.sim.value import Tracks, progress_from_tracks


def _sub(goal=None, beta=0.0, signal="grasped:cube", joint=None):
    return SimpleNamespace(
        object="cube",
        robot_points=["eef"],
        object_points=["cube"],
        goal=goal,
        beta=beta,
        end_signal=signal,
        joint=joint,
    )


SUBS = [_sub(), _sub("goal:bin", 0.8, "placed:cube")]
BOUNDS = [(0, 5), (6, 10)]


def _expert(n: int = 11) -> Tracks:
    """eef reaches the cube at x=1 (steps 0..5), then carries it to the goal at x=2."""
    eef = np.zeros((n, 3))
    eef[:, 0] = np.concatenate([np.linspace(0, 1, 6), np.linspace(1.2, 2, n - 6)])
    cube = np.zeros((n, 3))
    cube[:, 0] = np.maximum(eef[:, 0], 1.0)
    pts = {"eef": eef, "cube": cube, "goal:bin": np.tile([2.0, 0, 0], (n, 1))}
    return Tracks(pts, np.stack([eef, cube], axis=1))


def test_dropping_the_object_returns_progress_to_the_pick_up_stage():
    ex = _expert()
    q = np.array([0, 3, 6, 7, 8, 8])
    roll = ex.take(q)
    # at the last step the cube fell back to x=1 while the hand went on to x=1.6
    roll.points = {k: v.copy() for k, v in roll.points.items()}
    roll.points["cube"][5] = [1.0, 0, 0]
    roll.entities = np.stack([roll.points["eef"], roll.points["cube"]], axis=1)
    held = np.array([False, False, True, True, True, False])
    roll.kept = {"grasped:cube": held, "placed:cube": np.zeros(6, bool)}
    rover = progress_from_tracks(roll, q, ex, SUBS, BOUNDS)
    paper = progress_from_tracks(roll, q, ex, SUBS, BOUNDS, form="paper")
    assert rover[4] > 0.5  # carrying: past the pick-up stage
    assert rover[5] < 0.45  # dropped: back in the pick-up stage, hand away from the cube
    assert paper[5] == pytest.approx(0.5)  # the paper's form keeps the subtask's credit


def test_a_placed_object_keeps_the_grasp_stage_done_without_a_hand():
    ex = _expert()
    q = np.arange(11)
    roll = ex.take(q)
    roll.kept = {
        "grasped:cube": np.array([False] * 6 + [True] * 4 + [False]),
        "placed:cube": np.array([False] * 10 + [True]),
    }
    p = progress_from_tracks(roll, q, ex, SUBS, BOUNDS)
    assert p[-1] == pytest.approx(1.0)


def test_steps_after_the_goal_are_done_while_the_goal_stands():
    ex = _expert(14)  # steps 11..13: the hand backs off, the cube stays at the goal
    ex.points["eef"][11:, 0] = [1.8, 1.5, 1.2]
    ex.points["cube"][11:, 0] = 2.0
    ex.entities = np.stack([ex.points["eef"], ex.points["cube"]], axis=1)
    bounds = [(0, 5), (6, 13)]
    q = np.arange(14)
    rover = progress_from_tracks(ex, q, ex, SUBS, bounds, goal_end=10)
    paper = progress_from_tracks(ex, q, ex, SUBS, bounds, goal_end=10, form="paper")
    assert rover[10] == pytest.approx(1.0) and np.all(rover[10:] == pytest.approx(1.0))
    assert paper[10] < 0.99  # the paper's subtask runs on through the retreat


def test_joint_goal_rises_with_the_joint_even_if_the_object_point_never_moves():
    n = 11
    still = np.zeros((n, 3))  # the knob's centre: on its axis, never moves
    frac = np.linspace(0, 1, n)
    pts = {
        "eef": still.copy(),
        "cube": still.copy(),
        "tip": np.stack([0.03 * np.cos(frac), 0.03 * np.sin(frac), 0 * frac], axis=1),
        "goal:turned": np.tile([0.03 * np.cos(1), 0.03 * np.sin(1), 0], (n, 1)),
        "joint:knob": np.stack([frac, 0 * frac, 0 * frac], axis=1),
    }
    tracks = Tracks(pts, np.stack([still, still], axis=1))
    sub = SimpleNamespace(
        object="cube",
        robot_points=["eef"],
        object_points=["tip"],
        goal="goal:turned",
        beta=0.8,
        end_signal="turned:knob",
        joint="joint:knob",
    )
    p = progress_from_tracks(tracks, np.arange(n), tracks, [sub], [(0, n - 1)])
    assert p[-1] == pytest.approx(1.0)
    assert np.all(np.diff(p) > 0)  # every bit of turn shows
