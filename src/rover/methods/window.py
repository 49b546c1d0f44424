"""ROVER's sliding context window (paper Sec. 3, App. M).

With K frames the window holds the first frame of the current line of reasoning, the
K-2 most recent previous frames, and the current frame (K=3 is the paper's default:
first, most recent previous, current). `None` means no window: the whole line so far.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Seen:
    """A frame the line already reasoned about, with what the model said about it."""

    position: int
    description: str | None
    progress: float | None


def window_frames(first: Seen, history: list[Seen], window: int | None) -> list[Seen]:
    """Frames to show before the current one: the line's first frame + recent history.

    `history` is the line's previous frames in temporal order (the first frame excluded
    or included, it is dropped here); with `window=None` all of it is kept.
    """
    previous = [s for s in history if s.position != first.position]
    if window is not None:
        keep = max(window - 2, 0)
        previous = previous[-keep:] if keep else []
    return [first, *previous]


def validate_window(window: int | None) -> int | None:
    """Windows need room for the first and the current frame."""
    if window is not None and window < 2:
        from rover.errors import InputError

        raise InputError(f"--window must be at least 2 (first + current frame), got {window}")
    return window
