"""Normalisation statistics for a LeRobot export: `meta/stats.json` and per-episode stats.

Policies and reward models trained on LeRobot datasets normalise every feature with the
dataset's min / max / mean / std, read from `meta/stats.json`; the episode table carries the
same numbers per episode (columns ``stats/<feature>/<stat>``) so that subsets can be
re-aggregated without touching the frames. Numbers follow LeRobot's conventions: scalar
features reduce over frames to shape (1,); camera features reduce over frames, height and
width to one value per channel, shape (3, 1, 1), on pixels scaled to [0, 1], computed from
an even sample of each episode's frames (long episodes are sampled, not decoded whole).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rover.io.video import read_video

Stats = dict[str, np.ndarray]
SAMPLE_FLOOR = 100  # an episode shorter than this is read whole
SAMPLE_CAP = 10_000
SAMPLE_POWER = 0.75  # sample n**0.75 frames of a long episode
DOWNSAMPLE_ABOVE = 300  # px: larger frames are strided down to about ...
DOWNSAMPLE_TO = 150  # ... this many pixels on the long side before reducing


def column_stats(values: Sequence[float | int | None]) -> Stats | None:
    """Stats of one scalar feature over frames; None when no frame has a value."""
    arr = np.asarray([v for v in values if v is not None], dtype=np.float64)
    if arr.size == 0:
        return None
    return {
        "min": arr.min(keepdims=True),
        "max": arr.max(keepdims=True),
        "mean": arr.mean(keepdims=True),
        "std": arr.std(keepdims=True),
        "count": np.array([arr.size]),
    }


def sample_positions(n: int) -> list[int]:
    """Frame positions read for an episode of ``n`` frames (all of a short one)."""
    if n <= SAMPLE_FLOOR:
        return list(range(n))
    k = max(SAMPLE_FLOOR, min(int(n**SAMPLE_POWER), SAMPLE_CAP))
    return sorted(set(np.round(np.linspace(0, n - 1, k)).astype(int).tolist()))


def image_stats(frames: np.ndarray) -> Stats:
    """Per-channel stats of (T, H, W, 3) uint8 frames, as (3, 1, 1) arrays in [0, 1]."""
    h, w = frames.shape[1:3]
    if max(h, w) >= DOWNSAMPLE_ABOVE:
        step = max(1, max(h, w) // DOWNSAMPLE_TO)
        frames = frames[:, ::step, ::step]
    x = frames.astype(np.float64) / 255.0
    axes = (0, 1, 2)

    def per_channel(a: np.ndarray) -> np.ndarray:
        return a.reshape(3, 1, 1)

    return {
        "min": per_channel(x.min(axis=axes)),
        "max": per_channel(x.max(axis=axes)),
        "mean": per_channel(x.mean(axis=axes)),
        "std": per_channel(x.std(axis=axes)),
        "count": np.array([frames.shape[0]]),
    }


def video_stats(path: Path, num_frames: int) -> Stats:
    """Stats of one episode's camera video, from `sample_positions` of its frames."""
    return image_stats(read_video(path, sample_positions(num_frames)))


def merge_stats(parts: Sequence[Stats]) -> Stats:
    """Stats of the union of the parts: count-weighted mean, pooled variance."""
    counts = np.array([float(p["count"][0]) for p in parts])
    total = counts.sum()
    w = counts / total
    means = np.stack([p["mean"] for p in parts])
    shape = (-1,) + (1,) * (means.ndim - 1)
    mean = (means * w.reshape(shape)).sum(axis=0)
    second = np.stack([p["std"] ** 2 + (p["mean"] - mean) ** 2 for p in parts])
    var = (second * w.reshape(shape)).sum(axis=0)
    return {
        "min": np.min(np.stack([p["min"] for p in parts]), axis=0),
        "max": np.max(np.stack([p["max"] for p in parts]), axis=0),
        "mean": mean,
        "std": np.sqrt(np.maximum(var, 0.0)),
        "count": np.array([int(total)]),
    }


def as_json(stats: dict[str, Stats]) -> dict[str, dict[str, Any]]:
    """Nested lists, as `meta/stats.json` holds them."""
    return {k: {s: v.tolist() for s, v in st.items()} for k, st in sorted(stats.items())}


def episode_columns(stats: dict[str, Stats]) -> dict[str, Any]:
    """The ``stats/<feature>/<stat>`` columns of one episode's row."""
    return {f"stats/{k}/{s}": v.tolist() for k, st in sorted(stats.items()) for s, v in st.items()}
