"""Task 1 metrics: how well predicted progress tracks the ground truth (App. C.1).

Everything is on the 0..100 scale. Predictions are aligned to ground truth by the
*original frame index* each trace frame carries, never by loop position, so a trace made
on a 30-frame subsample scores correctly against a 240-frame episode and vice versa.

Undefined correlations follow GVL's convention for VOC: a constant prediction has no rank
order, scipy returns NaN, and we score it 0 while counting it (`*_constant` flags), so a
method that answers "50%" everywhere is penalised instead of silently dropped. A constant
*ground truth* (an attempt that never progresses) makes Pearson undefined whatever the
method did; that stays NaN and is left out of averages.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import stats

from rover.episode import Episode
from rover.methods.trace import Trace


@dataclass
class Aligned:
    """Predictions and truth for the frames a trace and an episode share."""

    indices: list[int]  # original frame indices, increasing
    positions: list[int]  # positions of those frames in the episode's truth arrays
    predicted: np.ndarray  # 0..100
    truth: np.ndarray  # 0..100


@dataclass
class ProgressScores:
    """Task 1 numbers for one trace."""

    n_frames: int
    pearson: float  # vs ground truth; 0 for constant predictions, NaN for constant truth
    pearson_constant: bool
    l2: float  # Euclidean norm of (predicted - truth) over the aligned frames
    voc: float  # Spearman of predictions vs frame order; constant -> 0
    voc_constant: bool
    frame_corr: float  # Pearson of predictions vs frame number; constant -> 0


def filled_predictions(trace: Trace) -> list[float]:
    """Per-frame progress, None filled forward from the last value (0 before any)."""
    out: list[float] = []
    last = 0.0
    for f in trace.frames:
        if f.progress is not None and not math.isnan(f.progress):
            last = float(f.progress)
        out.append(last)
    return out


def align(trace: Trace, episode: Episode) -> Aligned:
    """Pair each trace frame with the episode frame of the same original index."""
    if episode.truth is None:
        raise ValueError(f"episode {episode.id!r} has no ground truth to score against")
    where = {idx: pos for pos, idx in enumerate(episode.frame_indices)}
    preds = filled_predictions(trace)
    pairs = sorted(
        (f.index, where[f.index], p)
        for f, p in zip(trace.frames, preds, strict=True)
        if f.index in where
    )
    indices = [i for i, _, _ in pairs]
    positions = [pos for _, pos, _ in pairs]
    return Aligned(
        indices=indices,
        positions=positions,
        predicted=np.asarray([p for _, _, p in pairs], dtype=float),
        truth=np.asarray([episode.truth.progress[pos] * 100.0 for pos in positions], dtype=float),
    )


def _is_constant(x: np.ndarray) -> bool:
    return len(x) < 2 or bool(np.all(x == x[0]))


def pearson(pred: np.ndarray, truth: np.ndarray) -> tuple[float, bool]:
    """(r, prediction_was_constant); constant predictions score 0, constant truth NaN."""
    pred, truth = np.asarray(pred, float), np.asarray(truth, float)
    if len(pred) < 2 or _is_constant(truth):
        return math.nan, False
    return _correlation(stats.pearsonr, pred, truth)


def l2_distance(pred: np.ndarray, truth: np.ndarray) -> float:
    """Euclidean distance between the two progress curves (0..100 scale), App. C.1."""
    d = np.asarray(pred, float) - np.asarray(truth, float)
    return float(np.sqrt(np.sum(d * d)))


def voc(pred: np.ndarray, order: np.ndarray | None = None) -> tuple[float, bool]:
    """Value-order correlation (GVL): Spearman of predictions vs frame order."""
    pred = np.asarray(pred, float)
    order = np.arange(len(pred)) if order is None else np.asarray(order, float)
    if len(pred) < 2:
        return math.nan, False
    return _correlation(stats.spearmanr, pred, order)


def _correlation(fn, pred: np.ndarray, other: np.ndarray) -> tuple[float, bool]:
    """(statistic, prediction_was_constant): a constant or degenerate prediction scores 0."""
    if _is_constant(pred):
        return 0.0, True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = float(fn(pred, other).statistic)
    return (0.0, True) if math.isnan(r) else (r, False)


def score_progress(trace: Trace, episode: Episode) -> ProgressScores:
    """All Task 1 numbers for one trace against its episode's ground truth."""
    a = align(trace, episode)
    r, r_const = pearson(a.predicted, a.truth)
    v, v_const = voc(a.predicted, np.asarray(a.indices))
    fc, _ = pearson(a.predicted, np.asarray(a.indices, float))
    return ProgressScores(
        n_frames=len(a.indices),
        pearson=r,
        pearson_constant=r_const,
        l2=l2_distance(a.predicted, a.truth) if len(a.indices) else math.nan,
        voc=v,
        voc_constant=v_const,
        frame_corr=fc,
    )


def frame_subset_pearson(aligned: Aligned, keep: list[bool]) -> float:
    """Pearson over a subset of one trace's frames (for frame-level strata); NaN if < 3."""
    mask = np.asarray(keep, bool)
    if mask.sum() < 3:
        return math.nan
    r, _ = pearson(aligned.predicted[mask], aligned.truth[mask])
    return r


def frame_subset_abs_error(aligned: Aligned, keep: list[bool]) -> float:
    """Mean absolute error (0..100) over a subset of frames; NaN when empty."""
    mask = np.asarray(keep, bool)
    if not mask.any():
        return math.nan
    return float(np.mean(np.abs(aligned.predicted[mask] - aligned.truth[mask])))
