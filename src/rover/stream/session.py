"""A `Session` whose frames arrive one by one: what ROVER's core sees in a live stream.

`Rover.reason` asks for frames strictly in order through `has_frame`; here that call
waits until the next frame is pushed (True) or the stream is closed (False), so the same
code that reasons over a finished video reasons over a camera feed. Only the frames the
running lines can still show are kept: each open line's initial scene, its window of
previous frames and its last answered frame (ψ shows it to the parent). Frame and call
records (the trace) grow with the stream; pixels and encoded images do not.

With `record=False` the records are not kept either (a robot running for hours): calls
are counted into running totals, frame records and each line's stitch points are kept
only while a running line can still touch them, so memory stays flat; the trace at the
end is a summary (totals and the tree of lines, no per-frame records).
"""

from __future__ import annotations

import asyncio
from typing import Any

import numpy as np

from rover.methods.base import Method, OnStep, Session, is_oracle
from rover.methods.stitch import Point, StitchLine
from rover.methods.trace import CallRecord, FrameRecord, Totals, Trace
from rover.vlm.types import VLM


class LiveSession(Session):
    """A session fed by `add`; the reasoning task waits in `has_frame` for each frame."""

    memo_images = False  # every frame is seen once; `_parts` keeps the few still needed

    def __init__(
        self,
        method: Method,
        vlm: VLM,
        task: str,
        on_step: OnStep | None,
        episode_id: str = "stream",
        view: str | None = None,
        record: bool = True,
    ) -> None:
        self.episode = None  # type: ignore[assignment]  # no finished video behind it
        self.record = record
        self.frames: dict[int, np.ndarray] = {}
        self._begin(method, vlm, on_step)
        self.trace = Trace(
            method=method.name,
            params=dict(method.params),
            backend=vlm.backend,
            model=vlm.model,
            oracle=is_oracle(vlm),
            episode_id=episode_id,
            task=task,
            view=view,
            num_frames=0,
            frame_indices=[],
            frames=[],
        )
        if not record:  # stand-ins that count but keep only what is still needed
            self.trace.calls = _Tally()  # type: ignore[assignment]
            self.trace.frames = _Recent()  # type: ignore[assignment]
            self.trace.frame_indices = _Recent()  # type: ignore[assignment]
        self.closed = False
        self.waiting = asyncio.Event()  # set while the reasoning waits for a frame
        self._arrived = asyncio.Event()

    @property
    def num_frames(self) -> int:
        return len(self.trace.frames)

    def frame_index(self, position: int) -> int:
        return self.trace.frame_indices[position]

    async def has_frame(self, position: int) -> bool:
        while position >= self.num_frames:
            if self.closed:
                return False
            self._arrived.clear()
            self.waiting.set()
            await self._arrived.wait()
        self.waiting.clear()
        return True

    def add(self, frame: np.ndarray, index: int) -> int:
        """Append one frame (its original index); returns its position."""
        pos = self.num_frames
        self.trace.frame_indices.append(index)
        self.trace.frames.append(FrameRecord(index=index, position=pos))
        self.trace.num_frames = pos + 1
        self.frames[pos] = frame
        self.waiting.clear()
        self._arrived.set()
        return pos

    def close(self) -> None:
        """No more frames: the reasoning ends every open line at the last one."""
        self.closed = True
        self._arrived.set()

    def keep_only_needed(self) -> None:
        """Drop the pixels and encoded images no running line can show again."""
        need = {self.num_frames - 1}
        for line in self.open_lines:
            need.update(_line_positions(line))
        for store in (self.frames, self._parts):
            for pos in [p for p in store if p not in need]:
                del store[pos]
        if not self.record:
            for recent in (self.trace.frames, self.trace.frame_indices):
                recent.keep(need)  # type: ignore[attr-defined]
            if self.open_lines:
                _prune_points(self.open_lines[0].stitch)

    def totals(self) -> Totals:
        """Totals of every call made (also when calls are not kept)."""
        calls = self.trace.calls
        return calls.totals if isinstance(calls, _Tally) else self.trace.compute_totals()


def _line_positions(line: Any) -> set[int]:
    """Positions a running ROVER line may still show: initial scene, window, last answer."""
    out = {line.first.position, line.last_position}
    out.update(seen.position for seen in line.history)
    return out


class _Tally(list):
    """`Trace.calls` when calls are not kept: `len` counts them, `totals` sums them."""

    def __init__(self) -> None:
        super().__init__()
        self.count = 0
        self.totals = Totals()

    def append(self, rec: CallRecord) -> None:  # type: ignore[override]
        one = Trace(
            method="", backend="", model="", episode_id="", task="", num_frames=0,
            frame_indices=[], frames=[], calls=[rec],
        ).compute_totals()  # fmt: skip
        for name in Totals.model_fields:
            setattr(self.totals, name, getattr(self.totals, name) + getattr(one, name))
        self.count += 1

    def __len__(self) -> int:
        return self.count


class _Recent:
    """A list by position that keeps only the items still needed (`keep`)."""

    def __init__(self) -> None:
        self.count = 0
        self.items: dict[int, Any] = {}

    def append(self, item: Any) -> None:
        self.items[self.count] = item
        self.count += 1

    def __getitem__(self, position: int) -> Any:
        return self.items[position if position >= 0 else self.count + position]

    def __len__(self) -> int:
        return self.count

    def keep(self, positions: set[int]) -> None:
        for pos in [p for p in self.items if p not in positions]:
            del self.items[pos]


def _prune_points(line: StitchLine) -> None:
    """Keep each line's last point only (live values need no more; no trace is stitched)."""
    last = next((i for i in reversed(line.items) if isinstance(i, Point)), None)
    line.items = [i for i in line.items if not isinstance(i, Point) or i is last]
    for child in line.items:
        if isinstance(child, StitchLine):
            _prune_points(child)
