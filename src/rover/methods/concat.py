"""Frame-concatenation baselines (paper Sec. 5, App. H): frames in temporal order.

- `temporal-concat`: GVL without the shuffle; at timestep t the context holds frames
  0..t in order (frame 0 as the 0% initial scene) and the model answers for frame t.
- `local-concat`: only the last three frames (t-2, t-1, t) at each timestep.
- `video-concat`: the whole video in one call ("VideoGemini" in App. H), one answer
  per frame.
"""

from __future__ import annotations

from typing import Any

from rover.episode import Episode
from rover.methods.base import Method, OnStep, Session, text
from rover.methods.gvl import (
    FIRST_FRAME_DESCRIPTION,
    accumulating_parser,
    apply_answer,
    frames_missing,
    frames_usable,
    gather_limited,
)
from rover.methods.parse import FrameAnswer, parse_frame
from rover.methods.prompts import render
from rover.methods.trace import Trace
from rover.vlm.types import VLM, ImagePart, TextPart


class TemporalConcat(Method):
    """Ordered, growing context: frames 0..t, answer for frame t; one call per timestep."""

    name = "temporal-concat"
    local: int | None = None  # frames kept per call (None: all so far)

    def __init__(
        self,
        concurrency: int = 8,
        max_tokens: int | None = None,
        tokens_per_frame: int | None = None,
        **_ignored: Any,
    ) -> None:
        super().__init__()
        self.budget_options(max_tokens, tokens_per_frame)
        self.concurrency = int(concurrency)

    def context(self, t: int) -> list[int]:
        """Positions shown at timestep t, in temporal order, ending with t."""
        if self.local is None:
            return list(range(0, t + 1))
        return list(range(max(0, t - self.local + 1), t + 1))

    async def run(self, episode: Episode, vlm: VLM, on_step: OnStep | None = None) -> Trace:
        vlm = vlm.bind(episode)
        s = Session(self, episode, vlm, on_step)
        system = render("concat_system", task_description=episode.task)
        calls = [self._call(s, system, t) for t in range(1, s.num_frames)]
        await gather_limited(calls, self.concurrency)
        return s.finish()

    async def _call(self, s: Session, system: str, t: int) -> None:
        shown = self.context(t)
        await s.prefetch(shown)
        content: list[TextPart | ImagePart] = []
        for pos in shown:
            if pos == t:
                content += [text(f"Current frame (frame {t}):"), s.image(pos)]
            elif pos == 0:
                content += [
                    text("Initial robot scene (frame 0):"),
                    s.image(0),
                    text(
                        f"Frame description: {FIRST_FRAME_DESCRIPTION}\n"
                        "Task completion percentage: 0%"
                    ),
                ]
            else:
                content += [text(f"Frame {pos}:"), s.image(pos)]
        meta = s.meta("concat.frame", shown, extra={"target_position": t})
        ans, _ok = await s.ask(
            system,
            content,
            meta,
            parse_frame,
            lambda a: a.progress is not None,
            render("frame_reminder"),
        )
        apply_answer(s, t, ans)
        s.step(t, [], ans.progress)


class LocalConcat(TemporalConcat):
    """Local reasoning: only the last three frames in context at each timestep."""

    name = "local-concat"
    local = 3


class VideoConcat(Method):
    """The whole video in one call, answered frame by frame."""

    name = "video-concat"

    def __init__(
        self, max_tokens: int | None = None, tokens_per_frame: int | None = None, **_ignored: Any
    ) -> None:
        super().__init__()
        self.budget_options(max_tokens, tokens_per_frame)

    async def run(self, episode: Episode, vlm: VLM, on_step: OnStep | None = None) -> Trace:
        vlm = vlm.bind(episode)
        s = Session(self, episode, vlm, on_step)
        system = render("video_system", task_description=episode.task)
        n = s.num_frames
        await s.prefetch(list(range(n)))
        content: list[TextPart | ImagePart] = []
        for pos in range(n):
            content += [text(f"Frame {pos}:"), s.image(pos)]
        meta = s.meta("concat.video", list(range(n)), extra={"labels": list(range(n))})
        acc: dict[int, FrameAnswer] = {}
        reminder = render("frames_reminder", which=f"frames 0 to {n - 1}")
        answers, _ok = await s.ask(
            system,
            content,
            meta,
            accumulating_parser(acc),
            frames_usable(list(range(1, n))),
            reminder,
            frames=n,
            missing=frames_missing(list(range(1, n))),
        )
        for pos in range(n):
            apply_answer(s, pos, answers.get(pos))
        s.step(n - 1, [], None)
        return s.finish()
