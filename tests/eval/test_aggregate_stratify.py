"""Mean ± SE and the stratification keys."""

from __future__ import annotations

import math

import pytest

from rover.episode import StateType
from rover.eval.aggregate import group_mean_se, mean_se
from rover.eval.stratify import context_bin, context_frames, nonexpert_bin, nonexpert_share
from rover.methods.trace import CallRecord, FrameRecord, Trace


def test_mean_se_hand_computed_and_skips_nan() -> None:
    mean, se, n = mean_se([1.0, 2.0, 3.0, float("nan"), None])
    assert (mean, n) == (2.0, 3)
    assert se == pytest.approx(1.0 / math.sqrt(3))  # sd 1 over sqrt(3)
    assert math.isnan(mean_se([5.0])[1])
    assert mean_se([])[2] == 0


def test_group_mean_se() -> None:
    rows = [{"g": "a", "x": 1.0}, {"g": "a", "x": 3.0}, {"g": "b", "x": 5.0}, {"g": None, "x": 9}]
    out = group_mean_se(rows, "x", "g")
    assert out["a"][0] == 2.0 and out["b"][0] == 5.0 and None not in out


@pytest.mark.parametrize(
    ("n", "label"),
    [
        (1, "0-10"),
        (3, "0-10"),
        (10, "0-10"),
        (11, "10-20"),
        (30, "20-30"),
        (31, "30-40"),
        (0, None),
        (None, None),
    ],
)
def test_context_bins(n, label) -> None:
    assert context_bin(n) == label


def test_nonexpert_share_and_bins(make_episode) -> None:
    ep = make_episode(n=10)
    st = [StateType.expert] * 6 + [StateType.non_expert] * 3 + [StateType.interpolating]
    ep = ep.model_copy(update={"truth": ep.truth.model_copy(update={"state_type": st})})
    assert nonexpert_share(ep) == pytest.approx(0.3)
    assert nonexpert_bin(0.3) == "20-40%"
    assert nonexpert_bin(0.0) == "0-20%"
    assert nonexpert_bin(1.0) == "80-100%"


def test_context_frames_from_first_call_showing_each_frame() -> None:
    # TemporalConcat-like: call t shows frames 0..t
    calls = [
        CallRecord(id=t, kind="concat.frame", frame_indices=list(range(t + 1))) for t in range(4)
    ]
    tr = Trace(
        method="m",
        backend="b",
        model="x",
        episode_id="e",
        task="t",
        num_frames=4,
        frame_indices=[0, 1, 2, 3],
        calls=calls,
        frames=[FrameRecord(index=i, position=i) for i in range(4)],
    )
    assert context_frames(tr) == {0: 1, 1: 2, 2: 3, 3: 4}
    # ROVER-like: [line start, previous, current] -> 3 frames once the window is full
    calls = [
        CallRecord(id=0, kind="rover.step", frame_indices=[0]),
        CallRecord(id=1, kind="rover.step", frame_indices=[0, 1]),
        CallRecord(id=2, kind="rover.step", frame_indices=[0, 1, 2]),
        CallRecord(id=3, kind="rover.step", frame_indices=[0, 2, 3]),
    ]
    tr = tr.model_copy(update={"calls": calls})
    assert context_frames(tr) == {0: 1, 1: 2, 2: 3, 3: 3}
    # GVL-like: shuffled frames per timestep, calls recorded in completion order
    calls = [
        CallRecord(id=0, kind="gvl.batch", frame_indices=[2, 0, 1]),
        CallRecord(id=1, kind="gvl.batch", frame_indices=[1, 0]),
        CallRecord(id=2, kind="gvl.batch", frame_indices=[3, 1, 0, 2]),
    ]
    assert context_frames(tr.model_copy(update={"calls": calls})) == {0: 2, 1: 2, 2: 3, 3: 4}
    # one call showing everything (GVL single call): every frame had all 4 in context
    calls = [CallRecord(id=0, kind="gvl.batch", frame_indices=[3, 0, 2, 1])]
    assert context_frames(tr.model_copy(update={"calls": calls})) == {0: 4, 1: 4, 2: 4, 3: 4}
