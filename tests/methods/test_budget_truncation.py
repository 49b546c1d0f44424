"""Completion budgets sized to the request, truncation recorded and re-asked, and ROVER
driven end to end through a real OpenAI-compatible HTTP server writing like a model."""

from __future__ import annotations

import re

import pytest

from rover.methods import get_method
from rover.methods.budget import Budget, budget_for
from rover.methods.parse import parse_frames
from rover.vlm import load_vlm
from rover.vlm.config import BackendConfig
from rover.vlm.oracle import OracleBackend
from rover.vlm.testing import OpenAICompatServer
from rover.vlm.types import Prompt


class Recording:
    """Delegates to a VLM and keeps the sampling parameters of every call."""

    def __init__(self, inner) -> None:
        self.inner, self.backend, self.model = inner, inner.backend, inner.model
        self.params: list = []

    def bind(self, episode):
        self.inner = self.inner.bind(episode)
        return self

    async def complete(self, prompt, params=None):
        self.params.append(params)
        return await self.inner.complete(prompt, params)


def test_budget_rule():
    assert Budget("openai").tokens(1) == 512  # floor
    assert Budget("openai").tokens(30) == 30 * 60 + 64
    assert Budget("hf").tokens(240) == 4096  # cap
    assert Budget("gemini").tokens(1) == 2048  # thinking models spend output on thoughts
    assert Budget("openai", fixed=300).tokens(30) == 300
    explicit = OracleBackend(BackendConfig(max_tokens=77))
    assert budget_for(explicit).tokens(30) == 77  # --max-tokens wins
    assert budget_for(OracleBackend()).fixed is None


@pytest.mark.parametrize("method", ["gvl", "gvl-single", "video-concat"])
async def test_30_frames_get_the_budget_they_need(make_episode, method):
    vlm = Recording(OracleBackend())
    trace = await get_method(method).run(make_episode(30), vlm)
    assert max(p.max_tokens for p in vlm.params) >= 1200
    assert trace.totals.truncated_replies == 0 and trace.totals.parse_failures == 0
    assert all(f.predicted for f in trace.frames[1:])  # no frame lost


async def test_video_concat_cut_off_reply_is_reasked_for_the_missing_frames(make_episode):
    # a fixed budget too small for 30 frames: the oracle stops mid-reply, like a model
    vlm = Recording(OracleBackend())
    trace = await get_method("video-concat", max_tokens=700).run(make_episode(30), vlm)
    first, second = trace.calls
    assert first.truncated and first.finish_reason == "length" and first.parse == "retried"
    assert trace.totals.truncated_replies >= 1
    got_first = {k for k, a in parse_frames(first.response).items() if a.progress is not None}
    assert 0 < len(got_first) < 29
    # the re-ask names only the frames the cut-off reply did not reach
    assert set(map(int, re.findall(r"Frame (\d+):", second.response))).isdisjoint(got_first - {0})
    assert all(f.predicted for f in trace.frames[1:])
    assert trace.params["max_tokens"] == 700


async def test_scripted_model_truncates_and_rover_step_is_reasked(make_episode, scripted):
    long = "Frame description: " + "the arm moves " * 400 + "\nSubtask completion percentage: 40%"

    def script(p: Prompt) -> str:
        if p.meta.extra.get("reminder"):
            return "Frame description: short\nSubtask completion percentage: 40%\n[next-frame]"
        return long

    vlm = scripted(script)
    trace = await get_method("rover-no-recursion").run(make_episode(3), vlm)
    assert vlm.params[0].max_tokens == 512  # one frame asked: the floor
    cut = [c for c in trace.calls if c.truncated]
    assert cut and all(c.parse == "retried" for c in cut)
    assert trace.totals.truncated_replies == len(cut)
    assert trace.frames[2].subtask_progress == 40


def _text(body) -> str:
    out = []
    for m in body["messages"]:
        content = m["content"]
        parts = content if isinstance(content, list) else [{"type": "text", "text": content}]
        out += [p.get("text", "") for p in parts if p.get("type") == "text"]
    return "\n".join(out)


async def test_openai_server_two_subtask_plan_early_stop_scores_35(make_episode):
    """A model that plans two subtasks and stops at 70% of the first when the video ends."""
    ep = make_episode(8)
    steps = {"n": 0}

    def answer(body) -> str:
        system = body["messages"][0]["content"]
        if "subtask of pick the can and place it in the bin" in system:
            return (
                "**Frame description:** The gripper is open above the can.\n\n"
                "**New subtasks:** ['grasp the can', 'place the can in the bin']\n"
                "**The robot needs to:** grasp the can"
            )
        steps["n"] += 1
        # prose "needs to" inside the description must never start a line
        return (
            f"### Frame description\nThe gripper nears the can; the robot needs to close it "
            f"next.\n\n### Subtask completion percentage\n{10 * steps['n']}%\n\n[next-frame]"
        )

    config = BackendConfig(no_cache=True, retry_base_wait_s=0.001, max_retries=1, timeout_s=10)
    with OpenAICompatServer() as server:
        server.answer = answer
        vlm = load_vlm(f"openai:test-model@{server.base_url}", config)
        trace = await get_method("rover").run(ep, vlm)
        sent = [r.get("max_tokens") for r in server.requests]
    assert trace.progress()[-1] == pytest.approx(35, abs=1)
    assert len(trace.tree.children) == 1 and trace.tree.children[0].children == []
    assert trace.tree.planned_subtasks == ["grasp the can", "place the can in the bin"]
    assert trace.tree.children[0].outcome == "end_of_video"
    assert trace.frames[3].description.startswith("The gripper nears the can; the robot needs")
    assert all(s == 512 for s in sent)
