"""Trace JSON round trip, live step reports, tiny episodes and concurrent runs."""

from __future__ import annotations

import asyncio

import pytest

from rover.methods import Trace, get_method
from rover.methods.registry import NON_VLM_METHODS, method_names
from rover.vlm.oracle import OracleBackend

VLM_METHODS = [m for m in method_names() if m not in NON_VLM_METHODS]


async def test_trace_round_trip_and_totals(make_episode, tmp_path):
    steps = []
    trace = await get_method("rover").run(make_episode(12), OracleBackend(), steps.append)
    path = tmp_path / "t.json"
    trace.save(path)
    back = Trace.load(path)
    assert back == trace
    assert back.tree.children[1].first_frame == back.tree.children[0].last_frame
    t = back.totals
    assert t.calls == len(back.calls) and t.total_tokens == t.prompt_tokens + t.completion_tokens
    assert t.image_tokens == sum(c.image_tokens for c in back.calls) > 0
    assert all(c.latency_s >= 0 and c.cached is False for c in back.calls)
    assert [c.id for c in back.calls] == list(range(len(back.calls)))
    assert [s.position for s in steps] == list(range(12))  # one report per frame answered
    assert steps[8].subtask_path == ["place the can in the bin"] and steps[-1].calls == t.calls
    assert back.finished_at is not None


@pytest.mark.parametrize("name", VLM_METHODS)
@pytest.mark.parametrize("n", [1, 2, 3])
async def test_tiny_episodes(make_episode, name, n):
    ep = make_episode(10).select(list(range(n)))
    trace = await get_method(name).run(ep, OracleBackend())
    assert len(trace.frames) == n and trace.progress()[0] == 0
    assert all(0 <= p <= 100 for p in trace.progress())


async def test_one_method_instance_runs_episodes_concurrently(make_episode):
    method = get_method("rover")
    eps = [make_episode(8, episode_id="a"), make_episode(14, episode_id="b")]
    alone = [await method.run(ep, OracleBackend()) for ep in eps]
    together = await asyncio.gather(*(method.run(ep, OracleBackend()) for ep in eps))
    for x, y in zip(alone, together, strict=True):
        assert x.progress() == y.progress()
        assert x.tree.model_dump() == y.tree.model_dump()
