"""`RoverStream`: ROVER on a live camera feed, one pushed frame at a time.

    stream = RoverStream("open the drawer", vlm)
    for frame in camera:
        est = await stream.push(frame)      # FrameEstimate(progress, subtask_path, ...)
        if est.complete:
            break
    trace = await stream.trace()

It runs `Rover.reason`, the same code `rover reason` runs on a finished video, in a task
whose session (`LiveSession`) waits for each pushed frame, so pushing a video's frames
one by one gives exactly that video's trace. Per pushed frame it makes one step call
(two when the reply needs the format reminder), plus one parent turn per subtask switch;
it keeps only the frames the running lines can still show (`window=None`, the no-window
ablation, keeps each line's whole history by definition).

`FrameEstimate.progress` is the full-task value as stitched when the frame was answered.
`trace()` stitches once more over the whole stream; the two agree unless the model later
announced a longer plan than the one the value was scaled by (the trace then rescales the
earlier subtasks, as stitching a finished video does).
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from rover.errors import InputError
from rover.methods.base import StepInfo
from rover.methods.rover import Rover
from rover.methods.trace import Trace
from rover.stream.session import LiveSession
from rover.vlm.types import VLM

if TYPE_CHECKING:
    from rover.episode import Episode


@dataclass
class FrameEstimate:
    """What the stream knows after one pushed frame."""

    position: int  # 0-based count of pushed frames
    index: int  # the frame's index as pushed (default: its position)
    progress: float  # 0..100 over the full task, as stitched so far
    subtask_path: list[str] = field(default_factory=list)  # root task excluded
    description: str | None = None  # the model's description of this frame, if it gave one
    calls: int = 0  # VLM calls this frame cost (re-asks and parent turns included)
    complete: bool = False  # the task's line of reasoning has ended as complete


class RoverStream:
    """ROVER over frames pushed one by one (see the module docstring).

    Args:
        task: the task description (the root line's subtask).
        vlm: any backend; the oracle needs ground truth for the frames it is shown: a
            finished episode (`bind=`) or a live truth source (`rover.stream.LiveSimOracle`).
        bind: the episode to bind the VLM to (`vlm.bind(bind)`), e.g. a recorded video
            replayed as a stream; ignored by backends that read pixels.
        episode_id, view: recorded in the trace (default: the bound episode's, else
            "stream" and no view).
        record: keep every frame and call record for `trace()` (default). False keeps
            memory flat however long the stream runs: `trace()` is then a summary (totals
            and the tree of lines; no per-frame records, no calls).
        **params: ROVER's parameters (window, threshold, max_depth, ..., as `get_method`).
    """

    def __init__(
        self,
        task: str,
        vlm: VLM,
        *,
        bind: Episode | None = None,
        episode_id: str | None = None,
        view: str | None = None,
        method: str = "rover",
        record: bool = True,
        **params: Any,
    ) -> None:
        from rover.methods.registry import get_method

        if not task.strip():
            raise InputError("a stream needs a task description")
        m = get_method(method, **params)
        if not isinstance(m, Rover):
            raise InputError(f"streams run ROVER and its ablations, not {method!r}")
        if bind is not None:
            vlm = vlm.bind(bind)
            episode_id = episode_id or bind.id
            view = view or bind.view
        elif getattr(vlm, "backend", "") == "oracle" and not hasattr(vlm, "answer"):
            raise InputError(
                "the oracle answers from ground truth: pass bind=<episode> or use a live "
                "truth source (rover.stream.LiveSimOracle)"
            )
        self.method = m
        self.vlm = vlm
        self.task = task
        self._episode_id, self._view = episode_id or "stream", view
        self.record = record
        self._session: LiveSession | None = None
        self._job: asyncio.Task | None = None
        self._root: Any = None
        self._last: StepInfo | None = None
        self._final: Trace | None = None

    # -- feeding ---------------------------------------------------------------------------

    async def push(self, frame: np.ndarray, index: int | None = None) -> FrameEstimate:
        """Reason about one more frame; returns once ROVER waits for the next one."""
        if self._final is not None:
            raise InputError("this stream has ended (trace() was called)")
        frame = _check_frame(frame)
        s = self._start()
        if index is None:
            index = s.frame_index(s.num_frames - 1) + 1 if s.num_frames else 0
        elif s.num_frames and index <= s.frame_index(s.num_frames - 1):
            raise InputError(f"frame indices must increase: {index} after {s.frame_index(-1)}")
        before = len(s.trace.calls)
        pos = s.add(frame, int(index))
        await self._settle(s)
        s.keep_only_needed()
        fr = s.trace.frames[pos]
        last = self._last
        return FrameEstimate(
            position=pos,
            index=int(index),
            progress=0.0 if last is None or last.total is None else float(last.total),
            subtask_path=list(last.subtask_path) if last is not None else [],
            description=fr.description,
            calls=len(s.trace.calls) - before,
            complete=self.complete,
        )

    @property
    def complete(self) -> bool:
        """Whether the task's line ended as complete (later frames cost no calls)."""
        return self._root is not None and self._root.node.outcome == "complete"

    @property
    def frames_pushed(self) -> int:
        return 0 if self._session is None else self._session.num_frames

    def frames_held(self) -> int:
        """Frames whose pixels the stream still keeps (bounded by the open lines' windows)."""
        return 0 if self._session is None else len(self._session.frames)

    async def trace(self) -> Trace:
        """End the stream (idempotent) and return the trace of everything pushed."""
        if self._final is not None:
            return self._final
        if self._session is None:
            raise InputError("no frame was pushed: a trace needs at least one")
        s = self._session
        s.close()
        assert self._job is not None
        await self._job
        self._final = self.method.stitched(s, self._root) if self.record else _summary(s, self)
        return self._final

    async def aclose(self) -> None:
        """Stop without a trace (the reasoning task is cancelled)."""
        if self._job is not None and not self._job.done():
            self._job.cancel()
            try:
                await self._job
            except (asyncio.CancelledError, Exception):  # noqa: BLE001 - being discarded
                pass

    # -- internals -------------------------------------------------------------------------

    def _start(self) -> LiveSession:
        if self._session is None:
            s = LiveSession(
                self.method,
                self.vlm,
                self.task,
                self._on_step,
                self._episode_id,
                self._view,
                record=self.record,
            )
            self._session = s
            self._job = asyncio.get_running_loop().create_task(self._reason(s))
        return self._session

    async def _reason(self, s: LiveSession) -> None:
        self._root = await self.method.reason(s, self.task)

    def _on_step(self, info: StepInfo) -> None:
        self._last = info

    async def _settle(self, s: LiveSession) -> None:
        """Wait until the reasoning asks for the next frame, or has ended."""
        assert self._job is not None
        if not self._job.done():
            waiter = asyncio.ensure_future(s.waiting.wait())
            try:
                await asyncio.wait({waiter, self._job}, return_when=asyncio.FIRST_COMPLETED)
            finally:
                waiter.cancel()
        if self._job.done() and not self._job.cancelled() and self._job.exception():
            raise self._job.exception()  # type: ignore[misc]


def _summary(s: LiveSession, stream: RoverStream) -> Trace:
    """The trace of a stream that kept no records: its totals and its tree of lines."""
    from datetime import UTC, datetime

    return s.trace.model_copy(
        update={
            "params": {**s.trace.params, "record": False},
            "num_frames": s.num_frames,
            "frame_indices": [],
            "frames": [],
            "calls": [],
            "tree": stream._root.node,
            "totals": s.totals(),
            "finished_at": datetime.now(UTC).isoformat(),
        }
    )


def _check_frame(frame: Any) -> np.ndarray:
    arr = np.asarray(frame)
    if arr.ndim != 3 or arr.shape[-1] != 3 or arr.dtype != np.uint8:
        raise InputError(f"a frame must be uint8 (H, W, 3) RGB, got {arr.dtype} {arr.shape}")
    return arr
