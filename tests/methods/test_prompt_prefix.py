"""Prompt order for prefix caching (issue 14, item 4): what repeats across calls comes first.

Measured on the prompts the methods really send (`rover.vlm.prefix`), so a reorder that
moves a per-call part (the current frame, a previous frame) ahead of the stable parts
(system text, the line's initial scene and its description) fails here.
"""

from __future__ import annotations

import asyncio

import pytest

from rover.methods import get_method
from rover.vlm.config import BackendConfig
from rover.vlm.oracle import OracleBackend
from rover.vlm.prefix import PrefixTracker, openai_cached, prompt_segments, vllm_cached
from rover.vlm.types import ImagePart, Message, Prompt, PromptMeta, TextPart


class Recording:
    """The oracle, keeping every prompt in the order it was sent."""

    def __init__(self) -> None:
        self.inner = OracleBackend(BackendConfig(no_cache=True))
        self.backend, self.model = self.inner.backend, self.inner.model
        self.image_encoding = self.inner.image_encoding
        self.prompts: list[Prompt] = []

    def bind(self, episode):
        self._bound = self.inner.bind(episode)
        return self

    async def complete(self, prompt, params=None):
        self.prompts.append(prompt)
        return await self._bound.complete(prompt, params)


def _run(method: str, episode) -> list[Prompt]:
    vlm = Recording()
    asyncio.run(get_method(method, concurrency=1).run(episode, vlm))
    return vlm.prompts


def _share(prompts: list[Prompt]) -> float:
    tracker = PrefixTracker()
    for p in prompts:
        tracker.add(p)
    return tracker.share


def test_rover_steps_of_a_line_share_system_initial_scene_and_description(make_episode):
    prompts = _run("rover", make_episode(n=16))
    by_line: dict[int, list[Prompt]] = {}
    for p in prompts:
        if p.meta.kind == "rover.step":
            by_line.setdefault(p.meta.extra["line_id"], []).append(p)
    checked = 0
    for steps in by_line.values():
        windowed = [p for p in steps if len(p.images()) == 3]  # first, previous, current
        for a, b in zip(windowed, windowed[1:], strict=False):
            sa, sb = prompt_segments(a), prompt_segments(b)
            # role, system text, role, "Initial robot scene:", its image, its description
            assert sa[:6] == sb[:6]
            assert sa[4][0][0] == "image" and sa[4][0][1] == a.images()[0].image.sha256
            assert a.messages[1].parts()[0].text == "Initial robot scene:"
            assert sa[6] != sb[6] or sa[7] != sb[7]  # what follows is the moving window
            checked += 1
    assert checked >= 8


def test_rover_repeated_prefix_share_meets_the_target_at_30_frames(make_episode):
    share = _share(_run("rover", make_episode(n=30)))
    assert share >= 0.40


def test_the_growing_context_of_temporal_concat_is_almost_all_prefix(make_episode):
    prompts = _run("temporal-concat", make_episode(n=12))
    assert _share(prompts) > 0.6
    # GVL shuffles its frames: only the system text and the 0% anchor repeat
    gvl = _run("gvl", make_episode(n=12))
    for p in gvl:
        assert p.messages[0].role == "system"
        assert p.messages[1].parts()[0].text == "Initial robot scene:"
    assert 0.0 < _share(gvl) < _share(prompts)


def _prompt(*parts, system: str = "You watch robot videos.") -> Prompt:
    return Prompt(
        messages=[
            Message(role="system", content=system),
            Message(role="user", content=list(parts)),
        ],
        meta=PromptMeta(kind="t"),
    )


@pytest.fixture
def images():
    import numpy as np

    rng = np.random.default_rng(0)
    return [
        ImagePart.from_image(rng.integers(0, 255, (32, 32, 3), dtype=np.uint8)) for _ in range(3)
    ]


def test_tracker_counts_whole_images_and_common_leading_text_tokens(images):
    a, b, c = images
    t = PrefixTracker("gemini")
    first = _prompt(TextPart(text="Initial robot scene:"), a, TextPart(text="Current frame:"), b)
    assert t.add(first)[0] == 0
    repeated, total = t.add(first)  # the same prompt again: all of it
    assert repeated == total
    other = _prompt(TextPart(text="Initial robot scene:"), a, TextPart(text="Current frame:"), c)
    repeated, total = t.add(other)
    assert repeated == total - 258  # all but the last image (Gemini: 258 per small image)
    worded = _prompt(TextPart(text="Initial robot scene:"), a, TextPart(text="Current view:"), c)
    repeated, total = t.add(worded)
    prefix_len = sum(n for _, n in prompt_segments(worded)[:5])
    assert prefix_len < repeated < total - 258  # "Current" matched, the rest did not
    new_system = _prompt(a, system="Another system text.")
    assert t.add(new_system)[0] == 3  # only the system message's role mark


def test_provider_cache_granularity():
    assert [vllm_cached(n) for n in (15, 16, 611)] == [0, 16, 608]
    assert [openai_cached(n) for n in (1023, 1024, 1151, 1152)] == [0, 1024, 1024, 1152]
