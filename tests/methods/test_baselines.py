"""GVL, the concat baselines and the registry."""

from __future__ import annotations

import pytest

from rover.methods import get_method, method_names
from rover.methods.gvl import GVL
from rover.vlm.types import Prompt


def echo_progress(p: Prompt) -> str:
    """Answer every labelled frame with progress = 10 * its position."""
    m = p.meta
    if m.kind == "concat.frame":
        return f"Frame description: f\nTask completion percentage: {10 * m.positions[-1]}%"
    labels = m.extra["labels"]
    return "\n".join(
        f"Frame {lab}:\nFrame description: p{pos}\nTask completion percentage: {10 * pos}%"
        for pos, lab in zip(m.positions, labels, strict=True)
        if lab is not None
    )


def test_registry_names():
    assert method_names()[:3] == ["rover", "rover-no-window", "rover-no-recursion"]
    assert set(method_names()) >= {
        "gvl",
        "gvl-single",
        "temporal-concat",
        "local-concat",
        "video-concat",
        "clip-value",
    }
    m = get_method("gvl", window=3, seed=5)  # options a method does not use are ignored
    assert m.params == {"seed": 5}


async def test_gvl_anchor_and_seeded_shuffle(make_episode, scripted):
    ep = make_episode(9)
    vlm = scripted(echo_progress)
    trace = await get_method("gvl", seed=7).run(ep, vlm)
    assert len(vlm.prompts) == 8  # one call per timestep 1..8
    # calls run concurrently, so they may arrive in any order: sort them by timestep
    vlm.prompts.sort(key=lambda p: len(p.meta.frame_indices))
    for t, p in enumerate(vlm.prompts, start=1):
        shown = p.meta.frame_indices
        assert shown[0] == 0  # the 0% anchor comes first
        assert sorted(shown[1:]) == list(range(1, t + 1))  # all frames so far
        assert "Task completion percentage: 0%" in p.messages[1].content[2].text
    shuffles = [p.meta.frame_indices[1:] for p in vlm.prompts]
    assert any(s != sorted(s) for s in shuffles)
    assert shuffles == GVL(seed=7).permutations(9)
    assert GVL(seed=7).permutations(9) != GVL(seed=8).permutations(9)
    assert trace.progress() == pytest.approx([10.0 * t for t in range(9)])
    assert trace.frames[5].description == "p5"


async def test_gvl_single(make_episode, scripted):
    vlm = scripted(echo_progress)
    trace = await get_method("gvl-single", seed=1).run(make_episode(9), vlm)
    assert len(vlm.prompts) == 1
    assert vlm.prompts[0].meta.frame_indices[0] == 0
    assert sorted(vlm.prompts[0].meta.frame_indices) == list(range(9))
    assert trace.progress() == pytest.approx([10.0 * t for t in range(9)])


async def test_concat_windows(make_episode, scripted):
    ep = make_episode(6)
    vlm = scripted(echo_progress)
    await get_method("temporal-concat", concurrency=1).run(ep, vlm)
    assert [p.meta.frame_indices for p in vlm.prompts] == [list(range(t + 1)) for t in range(1, 6)]
    vlm = scripted(echo_progress)
    trace = await get_method("local-concat", concurrency=1).run(ep, vlm)
    assert [p.meta.frame_indices for p in vlm.prompts] == [
        [0, 1],
        [0, 1, 2],
        [1, 2, 3],
        [2, 3, 4],
        [3, 4, 5],
    ]
    assert trace.progress() == pytest.approx([0, 10, 20, 30, 40, 50])
    vlm = scripted(echo_progress)
    trace = await get_method("video-concat").run(ep, vlm)
    assert [p.meta.frame_indices for p in vlm.prompts] == [list(range(6))]
    assert trace.progress() == pytest.approx([0, 10, 20, 30, 40, 50])


async def test_batch_reask_merges_and_fills_forward(make_episode, scripted):
    replies = iter(
        [
            "Frame 0: 0%\nFrame 1: 10%\nFrame 2: 20%",  # frames 3..5 missing -> re-ask
            "Frame 3: 30%\nFrame 5: 50%",  # still missing 4 -> failed, 4 filled forward
        ]
    )
    vlm = scripted(lambda p: next(replies))
    trace = await get_method("video-concat").run(make_episode(6), vlm)
    assert [c.parse for c in trace.calls] == ["retried", "failed"]
    assert vlm.prompts[1].meta.extra["reminder"] is True
    assert trace.progress() == pytest.approx([0, 10, 20, 30, 30, 50])
    assert trace.frames[4].predicted is False
