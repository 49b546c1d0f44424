"""`rover eval` against a pool of two loopback replicas that report prefix-cache hits:
calls reach both, the run is one backend, and every cost view shows the cached share."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rover.cli import app
from rover.eval.variants import split_backend_specs
from rover.io.video import write_video
from rover.vlm.testing import OpenAICompatServer, Reply


def test_backend_lists_keep_a_pool_together():
    assert split_backend_specs("openai:m@http://a/v1,http://b/v1,oracle") == [
        "openai:m@http://a/v1,http://b/v1",
        "oracle",
    ]
    assert split_backend_specs("oracle, openai:m@https://a/v1") == [
        "oracle",
        "openai:m@https://a/v1",
    ]


def test_eval_over_a_pool_with_cached_tokens(tmp_path: Path) -> None:
    frames = np.zeros((6, 32, 32, 3), dtype=np.uint8)
    for t in range(6):
        frames[t, 8:16, 4 * t : 4 * t + 8] = (255, 40 * t, 40)
    video = tmp_path / "push.mp4"
    write_video(video, frames, fps=5)
    out = tmp_path / "run"
    with OpenAICompatServer() as a, OpenAICompatServer() as b:
        for s in (a, b):
            s.answer = lambda body: (
                "Frame description: the block moves.\nTask completion percentage: 40%"
            )
            s.script(*[Reply(delay_s=0.05, cached_tokens=100)] * 10)
        spec = f"openai:m@{a.base_url},{b.base_url.replace('http://', 'http://u:pool-secret@')}"
        args = ["eval", "--source", str(video), "--task", "push the block"]
        args += ["--methods", "temporal-concat", "--backend", spec, "--no-cache", "--out", str(out)]
        res = CliRunner().invoke(app, args, catch_exceptions=False)
        assert res.exit_code == 0, res.output
        assert a.count >= 1 and b.count >= 1 and a.count + b.count == 5
    assert "prefix cache: " in res.output
    metrics = json.loads((out / "metrics.json").read_text())
    cost = {c["metric"]: c for c in metrics["cost"]}
    assert cost["cached_prompt_tokens"]["mean"] == 500  # 5 calls x 100 reported
    assert cost["uncached_prompt_tokens"]["mean"] == cost["prompt_tokens"]["mean"] - 500
    assert "Cached prompt tokens" in (out / "summary.md").read_text()
    for name in ("run.json", "metrics.json", "summary.md"):
        assert "pool-secret" not in (out / name).read_text()
    assert "pool-secret" not in res.output
