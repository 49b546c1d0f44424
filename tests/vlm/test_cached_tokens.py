"""Provider-reported prompt-cache hits (issue 14, item 4): read into Usage, kept in traces,
split out in the one cost table every view reads."""

from __future__ import annotations

import asyncio

import pytest

from rover.eval.cost import cost_row, cost_table
from rover.eval.summary import _cost_table as summary_cost_table
from rover.eval.summary import prompt_cache_line
from rover.methods import get_method
from rover.vlm import load_vlm
from rover.vlm.cache import ResponseCache
from rover.vlm.testing import Reply
from rover.vlm.types import Usage


def test_openai_and_vllm_cached_tokens_are_read(openai_server, fast_config, make_prompt):
    openai_server.script(
        Reply(usage=(1200, 7), cached_tokens=1024),
        Reply(usage=(1200, 7), cached_tokens=5000),  # more than the prompt: capped
        Reply(usage=(1200, 7), cached_tokens=None),  # the field absent (no prefix caching)
    )
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    got = [asyncio.run(vlm.complete(make_prompt(f"q{i}"))).usage for i in range(3)]
    assert [(u.prompt_tokens, u.cached_prompt_tokens) for u in got] == [
        (1200, 1024),
        (1200, 1200),
        (1200, 0),
    ]
    assert got[0].uncached_prompt_tokens == 176 and got[0].source == "reported"


def test_gemini_cached_content_token_count_is_read(
    gemini_server, fast_config, make_prompt, monkeypatch
):
    pytest.importorskip("google.genai")
    monkeypatch.setenv("GEMINI_API_KEY", "AIzaTEST-gemini-key-000000000000")
    gemini_server.script(Reply(usage=(900, 5), cached_tokens=512))
    vlm = load_vlm(f"gemini:g@{gemini_server.base_url}", fast_config)
    usage = asyncio.run(vlm.complete(make_prompt())).usage
    assert (usage.prompt_tokens, usage.cached_prompt_tokens) == (900, 512)


def test_cached_counts_survive_the_response_cache(openai_server, fast_config, make_prompt):
    openai_server.script(Reply(usage=(300, 4), cached_tokens=256))
    spec = f"openai:m@{openai_server.base_url}"
    asyncio.run(load_vlm(spec, fast_config).complete(make_prompt()))
    again = asyncio.run(load_vlm(spec, fast_config).complete(make_prompt()))
    assert again.cached and again.usage.cached_prompt_tokens == 256


def test_old_cache_rows_and_usage_without_the_field_read_as_zero(tmp_path):
    cache = ResponseCache(tmp_path / "old.sqlite")
    old_usage = (
        '{"prompt_tokens": 10, "completion_tokens": 2, "image_tokens": 0, "source": "reported"}'
    )
    cache._conn().execute(
        "INSERT INTO responses VALUES (?, ?, ?, ?, ?, ?, ?)",
        ("k", "openai", "m", "hello", old_usage, 0.1, 0.0),
    )
    assert cache.get("k").usage.cached_prompt_tokens == 0
    assert Usage.model_validate({"prompt_tokens": 5}).cached_prompt_tokens == 0


def test_a_method_run_records_them_and_every_cost_view_splits_them(
    openai_server, fast_config, make_episode
):
    """temporal-concat over a server reporting a cache hit on every call after the first."""
    ep = make_episode(n=5)
    openai_server.answer = lambda body: "Frame description: x\nTask completion percentage: 10%"
    openai_server.script(
        Reply(usage=(500, 9), cached_tokens=0), *[Reply(usage=(500, 9), cached_tokens=384)] * 3
    )
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    trace = asyncio.run(get_method("temporal-concat", concurrency=1).run(ep, vlm))
    assert [c.cached_prompt_tokens for c in trace.calls] == [0, 384, 384, 384]
    assert trace.totals.cached_prompt_tokens == 3 * 384
    row = cost_row(trace)
    assert (row["cached_prompt_tokens"], row["uncached_prompt_tokens"]) == (1152, 2000 - 1152)
    rows = [{**row, "variant": "v", "method": "temporal-concat", "n_frames": 5}]
    table = {r["metric"]: r for r in cost_table(rows)}
    assert table["cached_prompt_tokens"]["mean"] == 1152
    assert table["uncached_prompt_tokens"]["mean"] == 848
    metrics = {"cost": cost_table(rows), "variants": [{"id": "v", "label": "TC", "view": None}]}
    cost = summary_cost_table(metrics)  # summary.md, the HTML report (run_tables) read this
    assert cost.headers[3:5] == ["Cached prompt tokens", "Uncached prompt tokens"]
    assert cost.rows[0][3:5] == ["1,152", "848"]
    # the terminal line after `rover eval`'s table reads the same rows
    assert prompt_cache_line(metrics) == (
        "prompt tokens served from the provider's prefix cache: TC 58%"
    )
    no_hits = [{**r, "cached_prompt_tokens": 0} for r in rows]
    assert prompt_cache_line({**metrics, "cost": cost_table(no_hits)}) is None


def test_rover_reason_names_the_providers_cached_part(openai_server, tmp_path):
    import numpy as np
    from typer.testing import CliRunner

    from rover.cli import app
    from rover.io.video import write_video

    frames = np.zeros((4, 32, 32, 3), dtype=np.uint8)
    for t in range(4):
        frames[t, 8:16, 6 * t : 6 * t + 8] = 255
    write_video(tmp_path / "v.mp4", frames, fps=5)
    openai_server.answer = lambda body: "Frame description: x\nTask completion percentage: 20%"
    openai_server.script(*[Reply(cached_tokens=50)] * 3)
    args = ["reason", str(tmp_path / "v.mp4"), "--task", "push", "--method", "temporal-concat"]
    args += ["--backend", f"openai:m@{openai_server.base_url}", "--no-cache"]
    res = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "t.json")])
    assert res.exit_code == 0, res.output
    assert "150 in the provider's prefix cache" in " ".join(res.output.split())
