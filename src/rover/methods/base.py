"""What every reasoning method shares: the interface, image parts, and a call recorder.

A method turns an Episode and a VLM into a Trace. The `Session` here makes each VLM
call, re-asks once with a format reminder when the reply cannot be used, and records
every call (frames sent, tokens, latency, cache hit, parse outcome) in the trace, so the
methods themselves only say *what* to ask and what to do with the answer.

Each call's completion budget is sized to the frames it asks about (`budget.py`). A reply
that stopped at that budget is recorded as truncated and, when frames are missing, re-asked
once for just those frames. CPU-heavy work (encoding frames, parsing long replies) runs in a
worker thread so one episode's parsing never stalls the other episodes' calls.
"""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any, TypeVar

from rover.episode import Episode
from rover.methods.budget import budget_for
from rover.methods.parse import reply_capped
from rover.methods.prompts import render
from rover.methods.trace import CallRecord, Trace
from rover.vlm.types import (
    VLM,
    Completion,
    EncodedImage,
    ImageEncoding,
    ImagePart,
    Message,
    Prompt,
    PromptMeta,
    SamplingParams,
    TextPart,
)

T = TypeVar("T")
_INLINE_PARSE_CHARS = 8192  # shorter replies parse in microseconds: no thread hop
_INLINE_ENCODE_PIXELS = 1_000_000  # fewer pixels encode in ~1 ms: cheaper than a thread hop
_ENCODE_LOCK = threading.Lock()  # the image memo is shared by every session's threads


@dataclass
class StepInfo:
    """Progress report for live displays (`on_step`): where the method is, what it said."""

    position: int  # sampled position just answered
    num_frames: int
    subtask_path: list[str] = field(default_factory=list)
    progress: float | None = None  # the value the model gave (its own line's scale)
    calls: int = 0
    total: float | None = None  # full-task value as stitched so far (ROVER), when known


OnStep = Callable[[StepInfo], None]


class Method:
    """Base of every reasoning method: a name, its parameters, and `run`."""

    name: str = ""

    max_tokens: int | None = None  # fixed completion budget per call (None: sized per call)
    tokens_per_frame: int | None = None  # budget per frame asked about (None: the default)

    def __init__(self, **params: Any) -> None:
        self.params: dict[str, Any] = params

    def budget_options(self, max_tokens: int | None, tokens_per_frame: int | None) -> None:
        """Keep the completion-budget overrides (recorded in params only when given)."""
        if max_tokens is not None:
            self.max_tokens = int(max_tokens)
            self.params["max_tokens"] = self.max_tokens
        if tokens_per_frame is not None:
            self.tokens_per_frame = int(tokens_per_frame)
            self.params["tokens_per_frame"] = self.tokens_per_frame

    async def run(self, episode: Episode, vlm: VLM, on_step: OnStep | None = None) -> Trace:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params})"


class Session:
    """One method run on one episode: encodes frames once, makes and records calls."""

    # the pixel-hash memo of encoded images (a live stream keeps its own few frames instead)
    memo_images = True

    def __init__(self, method: Method, episode: Episode, vlm: VLM, on_step: OnStep | None) -> None:
        self.episode = episode
        self.frames: Any = episode.frames()  # position -> pixels (a live stream: a few)
        self._begin(method, vlm, on_step)
        self.trace = Trace.start(
            episode, method.name, method.params, vlm.backend, vlm.model, oracle=is_oracle(vlm)
        )

    def _begin(self, method: Method, vlm: VLM, on_step: OnStep | None) -> None:
        """State every session has, whether its frames are a finished video or a stream."""
        self.vlm = vlm
        self.on_step = on_step
        self.encoding: ImageEncoding = getattr(vlm, "image_encoding", None) or ImageEncoding()
        self._parts: dict[int, ImagePart] = {}
        self.lines_started = 0  # ROVER: ids for lines of reasoning
        self.open_lines: list[Any] = []  # ROVER: the lines of reasoning running, root first
        self.budget = budget_for(vlm, method.max_tokens, method.tokens_per_frame)
        make = getattr(vlm, "default_params", None)
        self._params: SamplingParams = make() if callable(make) else SamplingParams()

    @property
    def num_frames(self) -> int:
        return self.episode.num_frames

    def frame_index(self, position: int) -> int:
        """Original index of the frame at a sampled position."""
        return self.episode.frame_indices[position]

    async def has_frame(self, position: int) -> bool:
        """Whether the video has a frame at `position` (a live stream waits to know)."""
        return position < self.num_frames

    def image(self, position: int) -> ImagePart:
        """The image part of one frame; each frame is encoded once per run."""
        part = self._parts.get(position)
        if part is None:
            with _ENCODE_LOCK:
                enc = EncodedImage.from_any(
                    self.frames[position], self.encoding, memo=self.memo_images
                )
            part = ImagePart(image=enc, frame_index=self.frame_index(position))
            self._parts[position] = part
        return part

    async def prefetch(self, positions: list[int]) -> None:
        """Encode the frames a prompt will show in a worker thread (the loop stays free)."""
        todo = [p for p in dict.fromkeys(positions) if p not in self._parts]
        pixels = sum(_pixels(self.frames[p]) for p in todo)
        if pixels > _INLINE_ENCODE_PIXELS:
            await asyncio.to_thread(lambda: [self.image(p) for p in todo])

    def params(self, frames: int) -> SamplingParams:
        """Sampling parameters for a call answering `frames` frames (its token budget)."""
        return self._params.model_copy(update={"max_tokens": self.budget.tokens(frames)})

    def meta(self, kind: str, positions: list[int], **kw: Any) -> PromptMeta:
        return PromptMeta(
            kind=kind,
            positions=list(positions),
            frame_indices=[self.frame_index(p) for p in positions],
            **kw,
        )

    async def ask(
        self,
        system: str,
        content: list[TextPart | ImagePart],
        meta: PromptMeta,
        parse: Callable[[str], T],
        usable: Callable[[T], bool],
        reminder: str,
        line_id: int | None = None,
        frames: int = 1,
        missing: Callable[[T], list[int]] | None = None,
    ) -> tuple[T, bool]:
        """Ask; on an unusable reply ask once more with a format reminder.

        `frames` is how many frames the reply must answer (it sizes the token budget).
        When the reply stopped at its budget and `missing(parsed)` names frame labels it
        did not reach, the re-ask asks for exactly those, with a budget for them.

        Returns (parsed reply, ok). When both replies are unusable, `ok` is False and the
        second reply's parse is returned so callers can salvage what is there.
        """
        messages = [Message(role="system", content=system), Message(role="user", content=content)]
        prompt = Prompt(messages=messages, meta=meta)
        params = self.params(frames)
        completion = await self._complete(prompt, params)
        parsed = await self._parse(parse, completion.text)
        if usable(parsed):
            self._record(prompt, completion, "ok", line_id, params)
            return parsed, True
        cut = self._record(prompt, completion, "retried", line_id, params).truncated
        gone = missing(parsed) if cut and missing is not None else []
        if gone:
            frames = len(gone)
            reminder = render("truncated_reminder", which=label_list(gone)) + "\n" + reminder
        retry = Prompt(
            messages=[
                *messages,
                Message(role="assistant", content=completion.text or "(empty reply)"),
                Message(role="user", content=reminder),
            ],
            meta=meta.model_copy(
                update={"extra": {**meta.extra, "reminder": True, "missing": list(gone)}}
            ),
        )
        params2 = self.params(frames)
        completion2 = await self._complete(retry, params2)
        parsed2 = await self._parse(parse, completion2.text)
        ok = usable(parsed2)
        # both calls stay in the trace: the first as "retried", this one "ok" or "failed"
        self._record(retry, completion2, "ok" if ok else "failed", line_id, params2)
        return parsed2, ok

    async def _parse(self, parse: Callable[[str], T], text: str) -> T:
        if len(text) <= _INLINE_PARSE_CHARS:
            return parse(text)
        return await asyncio.to_thread(parse, text)

    async def _complete(self, prompt: Prompt, params: SamplingParams) -> Completion:
        t0 = time.perf_counter()
        completion = await self.vlm.complete(prompt, params)
        if not completion.latency_s:
            completion = completion.model_copy(update={"latency_s": time.perf_counter() - t0})
        return completion

    def _record(
        self,
        prompt: Prompt,
        completion: Completion,
        parse: str,
        line_id: int | None,
        params: SamplingParams,
    ) -> CallRecord:
        u = completion.usage
        # cached replies lose the stop reason: a reply as long as the budget was cut too
        truncated = completion.truncated or u.completion_tokens >= params.max_tokens
        rec = CallRecord(
            id=len(self.trace.calls),
            kind=prompt.meta.kind,
            frame_indices=list(prompt.meta.frame_indices),
            line_id=line_id,
            subtask_path=list(prompt.meta.subtask_path),
            prompt_tokens=u.prompt_tokens,
            completion_tokens=u.completion_tokens,
            image_tokens=u.image_tokens,
            cached_prompt_tokens=u.cached_prompt_tokens,
            usage_source=u.source,
            latency_s=completion.latency_s,
            cached=completion.cached,
            parse=parse,  # type: ignore[arg-type]
            response=completion.text,
            max_tokens=params.max_tokens,
            finish_reason=completion.finish_reason,
            truncated=truncated,
            reply_capped=reply_capped(completion.text),
        )
        self.trace.calls.append(rec)
        return rec

    def step(
        self,
        position: int,
        subtask_path: list[str],
        progress: float | None,
        total: float | None = None,
    ) -> None:
        """Tell the live display a frame was answered (`total`: full-task value, if known)."""
        if self.on_step is not None:
            self.on_step(
                StepInfo(
                    position=position,
                    num_frames=self.num_frames,
                    subtask_path=list(subtask_path),
                    progress=progress,
                    calls=len(self.trace.calls),
                    total=total,
                )
            )

    def finish(self) -> Trace:
        """Totals and timestamps; frame 0 is 0 and gaps are filled forward."""
        last = 0.0
        for i, fr in enumerate(self.trace.frames):
            if i == 0:
                fr.progress = 0.0
            elif fr.progress is None:
                fr.progress = last
            last = fr.progress
        self.trace.totals = self.trace.compute_totals()
        self.trace.finished_at = datetime.now(UTC).isoformat()
        return self.trace


def is_oracle(vlm: VLM) -> bool:
    """Oracle answers stay labelled, also when replayed from a cassette the oracle recorded."""
    if vlm.backend == "oracle":
        return True
    recorded = getattr(vlm, "recorded_models", None)
    return vlm.backend == "replay" and recorded == ["ground-truth"]


def _pixels(frame: Any) -> int:
    shape = getattr(frame, "shape", None)
    if shape is not None and len(shape) >= 2:
        return int(shape[0]) * int(shape[1])
    size = getattr(frame, "size", None)  # PIL image
    return int(size[0]) * int(size[1]) if isinstance(size, tuple) else _INLINE_ENCODE_PIXELS + 1


def text(s: str) -> TextPart:
    return TextPart(text=s)


def label_list(labels: list[int]) -> str:
    """ "frame 3", "frames 3, 5 and 9", "frames 10 to 29" (runs of consecutive labels)."""
    labels = sorted(labels)
    if len(labels) == 1:
        return f"frame {labels[0]}"
    if labels == list(range(labels[0], labels[-1] + 1)):
        return f"frames {labels[0]} to {labels[-1]}"
    return "frames " + ", ".join(map(str, labels[:-1])) + f" and {labels[-1]}"
