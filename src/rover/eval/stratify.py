"""Stratification keys: which group a trace (or one of its frames) belongs to.

Trace-level strata (App. A, H–J, L): task group, level, share of non-expert states,
camera view, backend, frame count, window, dataset. Frame-level strata (App. G): the
state type at that frame and how many frames the method had in its context when it
predicted that frame.

Frames in context are read from the trace's call records, independent of the order calls
finished in (concurrent calls finish in any order): a frame's prediction comes from a call
whose *latest* frame is that frame (ROVER's "current frame" comes after its window;
GVL/TemporalConcat's call for timestep t shows frames up to t, in whatever order), the
largest such call if several (a ROVER step rather than its parent turn). Frames that are
never the latest of any call (a single-call method) take the smallest call showing them.
The count is the number of distinct frames that call sent.
"""

from __future__ import annotations

from rover.episode import Episode
from rover.methods.trace import Trace

CONTEXT_BIN = 10  # App. G bins: 0-10, 10-20, 20-30, ... frames
NONEXPERT_EDGES = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)


def context_frames(trace: Trace) -> dict[int, int]:
    """Original frame index -> number of frames in context when it was predicted."""
    as_latest: dict[int, int] = {}
    smallest: dict[int, int] = {}
    for call in trace.calls:
        frames = set(call.frame_indices)
        if not frames:
            continue
        n = len(frames)
        last = max(frames)
        as_latest[last] = max(as_latest.get(last, 0), n)
        for idx in frames:
            smallest[idx] = min(smallest.get(idx, n), n)
    return {idx: as_latest.get(idx, n) for idx, n in smallest.items()}


def context_bin(n: int | None) -> str | None:
    """'0-10' for 1..10 frames, '10-20' for 11..20, ... (None when unknown)."""
    if n is None or n <= 0:
        return None
    lo = ((n - 1) // CONTEXT_BIN) * CONTEXT_BIN
    return f"{lo}-{lo + CONTEXT_BIN}"


def nonexpert_share(episode: Episode) -> float | None:
    """Share of sampled frames that are non-expert (None without state labels)."""
    if episode.truth is None or not episode.truth.state_type:
        return None
    st = episode.truth.state_type
    return sum(1 for s in st if s == "non_expert") / len(st)


def nonexpert_bin(share: float | None) -> str | None:
    """'0-20%', '20-40%', ... ; an all-expert video falls in the first bin."""
    if share is None:
        return None
    edges = NONEXPERT_EDGES
    for lo, hi in zip(edges, edges[1:], strict=False):
        if share < hi or hi == edges[-1]:
            return f"{int(lo * 100)}-{int(hi * 100)}%"
    return None


def state_types(episode: Episode) -> dict[int, str]:
    """Original frame index -> state type label ('expert', 'non_expert', 'interpolating')."""
    if episode.truth is None or not episode.truth.state_type:
        return {}
    return {
        idx: str(s.value if hasattr(s, "value") else s)
        for idx, s in zip(episode.frame_indices, episode.truth.state_type, strict=True)
    }


def trace_strata(
    episode: Episode, trace: Trace, variant: dict, dataset: str | None = None
) -> dict[str, object]:
    """Every trace-level stratum label for one (episode, variant) row."""
    truth = episode.truth
    share = nonexpert_share(episode)
    return {
        "task_group": episode.task_group or "unknown",
        "level": None if truth is None or truth.level is None else int(truth.level),
        "nonexpert_share": share,
        "nonexpert": nonexpert_bin(share),
        "view": trace.view or episode.view,
        "backend": variant.get("backend"),
        "frames": episode.num_frames,  # what the method saw (a sweep value may exceed it)
        "window": variant.get("window"),
        "dataset": dataset,
    }


# trace-level stratifications reported in the aggregate tables, in display order
TRACE_STRATA = ("task_group", "level", "nonexpert", "view", "backend", "frames", "window")
FRAME_STRATA = ("state_type", "context")
