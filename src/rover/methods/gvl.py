"""GVL (Generative Value Learning, App. E.1) and its single-call variant.

GVL shows the first frame as a 0% anchor and the other frames in a random order, so the
model cannot lean on the temporal prior of steadily rising progress. The per-timestep
variant (`gvl`, used in the paper's comparisons) makes one call per timestep t with all
frames 1..t shuffled: this is why its token count grows quadratically with video length.
`gvl-single` asks once with every frame. Shuffles come from one seeded numpy Generator,
drawn in timestep order, so a seed fixes every permutation.
"""

from __future__ import annotations

import asyncio
from typing import Any

import numpy as np

from rover.episode import Episode
from rover.methods.base import Method, OnStep, Session, text
from rover.methods.parse import FrameAnswer, parse_frames
from rover.methods.prompts import render
from rover.methods.trace import Trace
from rover.vlm.types import VLM, ImagePart, TextPart

FIRST_FRAME_DESCRIPTION = "The initial robot scene, before the robot starts the task."


def frames_usable(needed: list[int]):
    """Usable when every needed label has a progress value."""

    def usable(answers: dict[int, FrameAnswer]) -> bool:
        return all(k in answers and answers[k].progress is not None for k in needed)

    return usable


def frames_missing(needed: list[int]):
    """The needed labels a reply left without a progress value (re-asked after a cut)."""

    def missing(answers: dict[int, FrameAnswer]) -> list[int]:
        return [k for k in needed if k not in answers or answers[k].progress is None]

    return missing


def accumulating_parser(acc: dict[int, FrameAnswer]):
    """parse_frames, merged into `acc` so a re-ask's answers fill the first reply's gaps."""

    def parse(reply: str) -> dict[int, FrameAnswer]:
        for k, ans in parse_frames(reply).items():
            prev = acc.get(k)
            if prev is None or ans.progress is not None:
                acc[k] = ans
        return acc

    return parse


def apply_answer(s: Session, position: int, ans: FrameAnswer | None) -> None:
    """Write one frame's answer into the trace (full-task progress, as the model gave it).

    Values below 0 (the prompts ask for negative progress after a regression) or above
    100 are kept; metrics decide whether to clip.
    """
    if ans is None:
        return
    fr = s.trace.frames[position]
    if ans.description:
        fr.description = ans.description
    if ans.progress is not None and position > 0:
        fr.progress = ans.progress
        fr.subtask_progress = ans.progress
        fr.predicted = True


async def gather_limited(coros: list, limit: int) -> None:
    """Run independent calls with at most `limit` in flight (backends bound it as well)."""
    sem = asyncio.Semaphore(max(1, limit))

    async def one(c):
        try:
            async with sem:
                await c
        finally:
            c.close()  # no-op once awaited; silences "never awaited" when cancelled early

    tasks = [asyncio.ensure_future(one(c)) for c in coros]
    if not tasks:
        return
    # On the first failure cancel the rest and retrieve every outcome, so the user sees
    # one error and asyncio never logs "exception was never retrieved".
    done, pending = await asyncio.wait(tasks, return_when=asyncio.FIRST_EXCEPTION)
    for t in pending:
        t.cancel()
    await asyncio.gather(*pending, return_exceptions=True)
    for t in tasks:
        if t.done() and not t.cancelled() and t.exception() is not None:
            raise t.exception()


class GVL(Method):
    """GVL: shuffled frames with the first frame as a 0% anchor; one call per timestep."""

    name = "gvl"
    per_timestep = True

    def __init__(
        self,
        seed: int = 0,
        concurrency: int = 8,
        max_tokens: int | None = None,
        tokens_per_frame: int | None = None,
        **_ignored: Any,
    ) -> None:
        super().__init__(seed=int(seed))
        self.budget_options(max_tokens, tokens_per_frame)
        self.seed = int(seed)
        self.concurrency = int(concurrency)

    def permutations(self, num_frames: int) -> list[list[int]]:
        """The shown order of positions 1..t for each call (seeded, drawn in order)."""
        rng = np.random.default_rng(self.seed)
        if not self.per_timestep:
            return [[int(p) + 1 for p in rng.permutation(num_frames - 1)]] if num_frames > 1 else []
        return [[int(p) + 1 for p in rng.permutation(t)] for t in range(1, num_frames)]

    async def run(self, episode: Episode, vlm: VLM, on_step: OnStep | None = None) -> Trace:
        vlm = vlm.bind(episode)
        s = Session(self, episode, vlm, on_step)
        system = render("gvl_system", task_description=episode.task)
        orders = self.permutations(s.num_frames)
        calls = [self._call(s, system, order) for order in orders]
        await gather_limited(calls, self.concurrency if self.per_timestep else 1)
        return s.finish()

    async def _call(self, s: Session, system: str, order: list[int]) -> None:
        await s.prefetch([0, *order])
        content: list[TextPart | ImagePart] = [
            text("Initial robot scene:"),
            s.image(0),
            text(f"Frame description: {FIRST_FRAME_DESCRIPTION}\nTask completion percentage: 0%"),
        ]
        for k, pos in enumerate(order, start=1):
            content += [text(f"Frame {k}:"), s.image(pos)]
        target = max(order)  # the newest frame: the one this timestep's call is for
        labels = list(range(1, len(order) + 1))
        needed = [order.index(target) + 1] if self.per_timestep else labels
        meta = s.meta(
            "gvl.batch",
            [0, *order],
            extra={"anchor": True, "labels": [None, *labels], "target_position": target},
        )
        acc: dict[int, FrameAnswer] = {}
        reminder = render(
            "frames_reminder", which=f"frames 1 to {len(order)}" if len(order) > 1 else "frame 1"
        )
        answers, _ok = await s.ask(
            system,
            content,
            meta,
            accumulating_parser(acc),
            frames_usable(needed),
            reminder,
            frames=len(order),  # the prompt asks for every shown frame
            missing=frames_missing(needed),
        )
        if self.per_timestep:
            apply_answer(s, target, answers.get(needed[0]))
            s.step(target, [], answers.get(needed[0], FrameAnswer()).progress)
        else:
            for k, pos in enumerate(order, start=1):
                apply_answer(s, pos, answers.get(k))
            s.step(s.num_frames - 1, [], None)


class GVLSingle(GVL):
    """GVL in one call: the anchor plus every other frame, shuffled."""

    name = "gvl-single"
    per_timestep = False
