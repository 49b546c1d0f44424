"""The one scorer: video-QA scores of a set of answers (Task 3, App. C.3).

Every view of a run reads QA numbers computed here, through metrics.json; nothing else
scores answers. Per video (one trace's answers) and pooled over a variant's questions,
the same function, so the per-video mean ± SE (the paper's main table) and the pooled
secondary table cannot disagree about what an answer is worth.

Rules, in one place:
- an unreadable answer (`predicted is None`) counts as *wrong* for accuracy and as "no"
  for precision / recall; it is never dropped (dropping it would score one right and one
  unreadable answer 100%, not 50%);
- accuracy, precision and recall are percentages (0-100);
- temporal distance is over true positives carrying both frames, in frames of the video
  the method saw: signed (predicted - true; negative = claimed too early, Fig. 6) and
  absolute.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np


class Answer(Protocol):
    truth: bool
    predicted: bool | None
    truth_frame: int | None
    predicted_frame: int | None


def _mean(values: Sequence[float]) -> float:
    return float(np.mean(values)) if len(values) else math.nan


def signed_distances(answers: Sequence[Answer]) -> list[int]:
    """predicted - true frame for every true positive that carries both frames."""
    return [
        a.predicted_frame - a.truth_frame
        for a in answers
        if a.predicted and a.truth and a.predicted_frame is not None and a.truth_frame is not None
    ]


def qa_scores(answers: Sequence[Answer]) -> dict[str, Any]:
    """Accuracy, precision, recall (%) and temporal distances over a set of answers."""
    n = len(answers)
    if n == 0:
        return {
            "qa_n": 0,
            "unreadable": 0,
            "accuracy": math.nan,
            "precision": math.nan,
            "recall": math.nan,
            "signed_distance": math.nan,
            "abs_distance": math.nan,
            "distance_n": 0,
        }
    correct = sum(a.predicted is not None and a.predicted == a.truth for a in answers)
    tp = sum(bool(a.predicted) and a.truth for a in answers)
    fp = sum(bool(a.predicted) and not a.truth for a in answers)
    fn = sum(not a.predicted and a.truth for a in answers)
    dists = signed_distances(answers)
    return {
        "qa_n": n,
        "unreadable": sum(a.predicted is None for a in answers),
        "accuracy": 100.0 * correct / n,
        "precision": 100.0 * tp / (tp + fp) if tp + fp else math.nan,
        "recall": 100.0 * tp / (tp + fn) if tp + fn else math.nan,
        "signed_distance": _mean(dists),
        "abs_distance": _mean([abs(d) for d in dists]),
        "distance_n": len(dists),
    }
