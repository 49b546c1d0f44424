"""Task 1 metrics on inputs small enough to check by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rover.eval.progress_metrics import align, l2_distance, pearson, score_progress, voc
from rover.methods.trace import FrameRecord, Trace


def _trace(indices: list[int], progress: list[float | None], episode_id: str = "ep0") -> Trace:
    return Trace(
        method="m",
        backend="b",
        model="x",
        episode_id=episode_id,
        task="t",
        num_frames=len(indices),
        frame_indices=indices,
        frames=[
            FrameRecord(index=i, position=p, progress=v)
            for p, (i, v) in enumerate(zip(indices, progress, strict=True))
        ],
    )


def test_pearson_hand_computed() -> None:
    # x = [0, 50, 100], y = [0, 25, 100]: mean x 50, mean y 41.67
    # cov = (-50)(-41.67) + 0 + 50(58.33) = 5000; sx = sqrt(5000); sy = sqrt(41.67²+16.67²+58.33²)
    x, y = np.array([0.0, 50, 100]), np.array([0.0, 25, 100])
    sy = math.sqrt(41.6667**2 + 16.6667**2 + 58.3333**2)
    expected = 5000 / (math.sqrt(5000) * sy)
    r, const = pearson(x, y)
    assert r == pytest.approx(expected, abs=1e-4) and not const


def test_pearson_constant_prediction_scores_zero_and_is_flagged() -> None:
    assert pearson(np.array([50.0, 50, 50]), np.array([0.0, 50, 100])) == (0.0, True)


def test_pearson_constant_truth_is_undefined() -> None:
    r, const = pearson(np.array([0.0, 50, 100]), np.array([0.0, 0, 0]))
    assert math.isnan(r) and not const


def test_l2_is_euclidean_norm_on_0_100_scale() -> None:
    assert l2_distance(np.array([0.0, 50, 100]), np.array([0.0, 20, 60])) == pytest.approx(50.0)


def test_voc_ranks_against_frame_order() -> None:
    assert voc(np.array([0.0, 10, 20, 30]))[0] == pytest.approx(1.0)
    assert voc(np.array([30.0, 20, 10, 0]))[0] == pytest.approx(-1.0)
    # one swapped pair among 4: rho = 1 - 6*2/(4*15) = 0.8
    assert voc(np.array([0.0, 20, 10, 30]))[0] == pytest.approx(0.8)


def test_voc_constant_is_zero_and_counted() -> None:
    assert voc(np.array([42.0, 42, 42])) == (0.0, True)


def test_alignment_uses_original_indices_with_subsampled_trace(make_episode) -> None:
    ep = make_episode(n=11)  # truth progress t/10 at original index t
    # a method that saw only indices 0, 5, 10 (a 3-frame subsample), listed out of order
    tr = _trace([10, 0, 5], [100.0, 0.0, 50.0])
    a = align(tr, ep)
    assert a.indices == [0, 5, 10]
    assert list(a.truth) == [0.0, 50.0, 100.0]
    assert list(a.predicted) == [0.0, 50.0, 100.0]
    s = score_progress(tr, ep)
    assert s.pearson == pytest.approx(1.0) and s.l2 == pytest.approx(0.0) and s.n_frames == 3


def test_alignment_after_episode_subsample(make_episode) -> None:
    ep = make_episode(n=21).subsample(5)  # original indices 0, 5, 10, 15, 20
    assert ep.frame_indices == [0, 5, 10, 15, 20]
    tr = _trace(ep.frame_indices, [0.0, 25.0, 50.0, 75.0, 100.0])
    s = score_progress(tr, ep)
    assert s.l2 == pytest.approx(0.0)
    # a loop-position alignment against the full episode would be wrong: index 5 is 25%
    s_full = score_progress(tr, make_episode(n=21))
    assert s_full.l2 == pytest.approx(0.0)


def test_missing_predictions_fill_forward(make_episode) -> None:
    ep = make_episode(n=5)
    tr = _trace([0, 1, 2, 3, 4], [None, 25.0, None, None, 100.0])
    a = align(tr, ep)
    assert list(a.predicted) == [0.0, 25.0, 25.0, 25.0, 100.0]


def test_frame_corr_is_against_frame_number(make_episode) -> None:
    ep = make_episode(n=5)
    tr = _trace([0, 1, 2, 3, 4], [0.0, 10.0, 20.0, 30.0, 40.0])
    assert score_progress(tr, ep).frame_corr == pytest.approx(1.0)
